# Sessions on the built Tissue.fmu through the host's importer (never linking the core).
add_executable(test_fmu_sessions ${CMAKE_CURRENT_LIST_DIR}/test_fmu_sessions.cpp)
target_link_libraries(test_fmu_sessions PRIVATE tissue::fmi_importer tissue::ports tissue::warnings GTest::gtest GTest::gtest_main)
target_compile_definitions(test_fmu_sessions PRIVATE TISSUE_FMU_PATH="${TISSUE_TISSUE_FMU_PATH}"
                                                     TISSUE_MESH_DIR="${PROJECT_SOURCE_DIR}/meshes"
                                                     FMU_STATE_SEEDS="${PROJECT_SOURCE_DIR}/fuzz/corpus/fmu_state")
add_dependencies(test_fmu_sessions tissue_fmu_package)
gtest_discover_tests(test_fmu_sessions PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)

# tissue_add_range_test(<name> FMU <path> PACKAGE <target>): declared min/max = enforced range.
function(tissue_add_range_test name)
  cmake_parse_arguments(ARG "" "FMU;PACKAGE" "" ${ARGN})
  add_executable(${name} ${CMAKE_CURRENT_LIST_DIR}/test_fmu_ranges.cpp)
  target_link_libraries(${name} PRIVATE tissue::fmi_importer tissue::warnings GTest::gtest GTest::gtest_main)
  target_compile_definitions(${name} PRIVATE TISSUE_FMU_PATH="${ARG_FMU}")
  add_dependencies(${name} ${ARG_PACKAGE})
  gtest_discover_tests(${name} PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60 TEST_PREFIX "${name}.")
endfunction()

tissue_add_range_test(test_tissue_fmu_ranges FMU ${TISSUE_TISSUE_FMU_PATH} PACKAGE tissue_fmu_package)
tissue_add_range_test(test_haptic_loop_fmu_ranges FMU ${TISSUE_HAPTICLOOP_FMU_PATH} PACKAGE hapticloop_fmu_package)

# Sessions on the built HapticLoop.fmu, driven as the real-time host drives it.
add_executable(test_haptic_loop_sessions ${CMAKE_CURRENT_LIST_DIR}/test_haptic_loop_sessions.cpp)
# The tissue sample and its delivery are the closed-loop harness's (hand_on_tissue.hpp, below).
target_link_libraries(test_haptic_loop_sessions PRIVATE tissue_hand_on_tissue tissue::fmi_importer tissue::warnings
                                                        GTest::gtest GTest::gtest_main)
add_dependencies(test_haptic_loop_sessions hapticloop_fmu_package)
gtest_discover_tests(test_haptic_loop_sessions PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)

# The haptic path through the FMU allocates nothing; its own executable because it replaces the
# global operator new (which HapticLoop.so binds to as well).
add_executable(test_haptic_loop_allocations ${CMAKE_CURRENT_LIST_DIR}/test_haptic_loop_allocations.cpp)
target_link_libraries(test_haptic_loop_allocations PRIVATE tissue::fmi_importer tissue::warnings GTest::gtest
                                                           GTest::gtest_main)
target_include_directories(test_haptic_loop_allocations PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_compile_definitions(test_haptic_loop_allocations PRIVATE HAPTIC_LOOP_FMU_PATH="${TISSUE_HAPTICLOOP_FMU_PATH}")
add_dependencies(test_haptic_loop_allocations hapticloop_fmu_package)
gtest_discover_tests(test_haptic_loop_allocations PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)

# The closed-loop harness of issue 20: a simulated hand on HapticLoop.fmu, synthetic tissues sampled
# at 100 Hz one step late; its tests, and hand_on_walls, the table it measures (docs/BENCHMARKS.md).
add_library(tissue_hand_on_tissue STATIC ${CMAKE_CURRENT_LIST_DIR}/hand_on_tissue.cpp)
target_include_directories(tissue_hand_on_tissue PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(tissue_hand_on_tissue PUBLIC tissue::host_device tissue::fmi_importer PRIVATE tissue::warnings)
target_compile_definitions(tissue_hand_on_tissue PRIVATE HAPTIC_LOOP_FMU_PATH="${TISSUE_HAPTICLOOP_FMU_PATH}")
add_dependencies(tissue_hand_on_tissue hapticloop_fmu_package)
add_executable(test_haptic_loop_hand ${CMAKE_CURRENT_LIST_DIR}/test_haptic_loop_hand.cpp)
target_link_libraries(test_haptic_loop_hand PRIVATE tissue_hand_on_tissue GTest::gtest GTest::gtest_main tissue::warnings)
target_include_directories(test_haptic_loop_hand PRIVATE ${PROJECT_SOURCE_DIR}/tests)
gtest_discover_tests(test_haptic_loop_hand PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)
add_executable(hand_on_walls ${CMAKE_CURRENT_LIST_DIR}/hand_on_walls.cpp)
target_link_libraries(hand_on_walls PRIVATE tissue_hand_on_tissue tissue::warnings)

# z_width: the Z-width chart (docs/z_width.png): the stiffest wall each hand settles on, for an ideal
# 1 kHz wall and through HapticLoop.fmu with and without K_c (a tool, not a test).
add_executable(z_width ${CMAKE_CURRENT_LIST_DIR}/z_width.cpp)
target_link_libraries(z_width PRIVATE tissue_hand_on_tissue tissue::host_compare tissue::host_output tissue::warnings)

# The Tissue FMU's background job (its thread and policy), linked from the model's library.
