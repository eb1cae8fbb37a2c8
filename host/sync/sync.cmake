# tissue::host_sync - what the host's threads keep time and exchange values with: the clocks and
# real-time priority (realtime_clock.hpp), the lock-free latest value (latest_value.hpp) and the
# frame pipe to the writer (frame_pipe.hpp). Included from host/CMakeLists.txt (after output/).
add_library(tissue_host_sync STATIC ${CMAKE_CURRENT_LIST_DIR}/realtime_clock.cpp)
add_library(tissue::host_sync ALIAS tissue_host_sync)
target_include_directories(tissue_host_sync PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_sync PUBLIC cxx_std_20)
target_link_libraries(tissue_host_sync PUBLIC tissue::host_output Threads::Threads PRIVATE tissue::warnings)
