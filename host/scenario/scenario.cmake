# tissue::host_scenario - scenario files (toml++): the session's timing, the two FMUs' parameters and
# the device. Included from host/CMakeLists.txt.
find_package(tomlplusplus REQUIRED)
add_library(tissue_host_scenario STATIC ${CMAKE_CURRENT_LIST_DIR}/scenario.cpp)
add_library(tissue::host_scenario ALIAS tissue_host_scenario)
target_include_directories(tissue_host_scenario PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_scenario PUBLIC cxx_std_20)
target_link_libraries(tissue_host_scenario PUBLIC tissue::host_device PRIVATE tomlplusplus::tomlplusplus tissue::warnings)
