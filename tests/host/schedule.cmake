# Tests of tissue::host_schedule (label "host"): the rules the schedulers follow, without threads or
# clocks (the sessions' tests run the schedulers themselves).
if(NOT TARGET tissue::host_schedule)
  return()
endif()
add_executable(test_host_schedule ${CMAKE_CURRENT_LIST_DIR}/test_frame_budget.cpp)
target_link_libraries(test_host_schedule PRIVATE tissue::host_schedule GTest::gtest GTest::gtest_main tissue::warnings)
gtest_discover_tests(test_host_schedule PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)
