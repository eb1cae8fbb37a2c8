# Tests of tissue::host_schedule (label "host"): the rules the schedulers follow, without threads or
# clocks (the sessions' tests run the schedulers themselves), the real-time memory recipe, and the
# machine's timer check (counts only, never its timing).
if(NOT TARGET tissue::host_schedule)
  return()
endif()
add_executable(test_host_schedule ${CMAKE_CURRENT_LIST_DIR}/test_frame_budget.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/test_memory_reserve.cpp
                                  ${CMAKE_CURRENT_LIST_DIR}/test_timer_check.cpp)
target_link_libraries(test_host_schedule PRIVATE tissue::host_schedule GTest::gtest GTest::gtest_main tissue::warnings)
target_include_directories(test_host_schedule PRIVATE ${PROJECT_SOURCE_DIR}/tests)  # support/under_sanitizer.hpp
gtest_discover_tests(test_host_schedule PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

# The links' recycled byte buffers (header-only; the FMU links themselves run in the session tests).
if(TARGET tissue::host_links)
  add_executable(test_host_links ${CMAKE_CURRENT_LIST_DIR}/test_recycled_bytes.cpp)
  target_link_libraries(test_host_links PRIVATE tissue::host_links GTest::gtest GTest::gtest_main tissue::warnings)
  gtest_discover_tests(test_host_links PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)
endif()
