# The haptic rendering core (libtissue/haptic). Not tissue_add_test: that links the FEM core,
# and the haptic core must build and test without it.
add_executable(test_haptic
  ${CMAKE_CURRENT_LIST_DIR}/test_contact_force.cpp ${CMAKE_CURRENT_LIST_DIR}/test_force_limits.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_cutting_force.cpp ${CMAKE_CURRENT_LIST_DIR}/test_passivity.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_haptic_renderer.cpp ${CMAKE_CURRENT_LIST_DIR}/test_normal_model_estimate.cpp)
target_link_libraries(test_haptic PRIVATE tissue::haptic_core tissue::warnings GTest::gtest GTest::gtest_main)
target_include_directories(test_haptic PRIVATE ${PROJECT_SOURCE_DIR}/tests)
# Two labels: LABELS "unit;physics" loses its ';' on the way through the discovery script (CMake
# issue 17812; the tests got "unit" only), so the property is given twice, which appends.
gtest_discover_tests(test_haptic PROPERTIES LABELS unit LABELS physics DISCOVERY_TIMEOUT 60)

# Counts operator new across ticks; its own executable because it replaces the global allocator.
add_executable(test_haptic_allocations ${CMAKE_CURRENT_LIST_DIR}/test_haptic_allocations.cpp)
target_link_libraries(test_haptic_allocations PRIVATE tissue::haptic_core tissue::warnings GTest::gtest
                                                      GTest::gtest_main)
target_include_directories(test_haptic_allocations PRIVATE ${PROJECT_SOURCE_DIR}/tests)
gtest_discover_tests(test_haptic_allocations PROPERTIES LABELS "unit" DISCOVERY_TIMEOUT 60)
