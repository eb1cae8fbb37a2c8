# tissue::host_schedule - when a session's steps run: the timeline (schedule.hpp), the steps a session
# implements (session_steps.hpp), the offline scheduler and the real-time one (haptic and dynamics
# threads, overrun policy, frame writing). Included from host/CMakeLists.txt (after output/ and sync/);
# knows no session, no FMU and no view.
add_library(tissue_host_schedule STATIC
  ${CMAKE_CURRENT_LIST_DIR}/schedule.cpp
  ${CMAKE_CURRENT_LIST_DIR}/offline_schedule.cpp
  ${CMAKE_CURRENT_LIST_DIR}/realtime_schedule.cpp
  ${CMAKE_CURRENT_LIST_DIR}/memory_reserve.cpp
  ${CMAKE_CURRENT_LIST_DIR}/timer_check.cpp)
add_library(tissue::host_schedule ALIAS tissue_host_schedule)
target_include_directories(tissue_host_schedule PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_schedule PUBLIC cxx_std_20)
target_link_libraries(tissue_host_schedule
  PUBLIC tissue::host_scenario tissue::host_output tissue::host_sync Threads::Threads
  PRIVATE tissue::warnings)
