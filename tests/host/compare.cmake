# Tests of tissue-host compare (label "host"): its pieces without an FMU (test_host_compare), and
# whole comparisons on the built FMUs, on threads, under mpirun, and refused mistakes
# (test_host_compare_runs; it runs the tissue-host executable for exit codes and MPI).
if(NOT TARGET tissue::host_compare)
  return()
endif()
find_package(PNG REQUIRED)

add_executable(test_host_compare ${CMAKE_CURRENT_LIST_DIR}/test_compare.cpp)
target_include_directories(test_host_compare PRIVATE ${CMAKE_CURRENT_LIST_DIR})
find_package(nlohmann_json REQUIRED)
target_link_libraries(test_host_compare PRIVATE tissue::host_compare PkgConfig::TISSUE_LIBZIP nlohmann_json::nlohmann_json
                                                GTest::gtest GTest::gtest_main tissue::warnings)
gtest_discover_tests(test_host_compare PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

add_executable(test_host_compare_runs ${CMAKE_CURRENT_LIST_DIR}/test_compare_runs.cpp)
target_include_directories(test_host_compare_runs PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(test_host_compare_runs PRIVATE tissue::host_compare PNG::PNG PkgConfig::TISSUE_LIBZIP
                                                     GTest::gtest GTest::gtest_main tissue::warnings)
target_compile_definitions(test_host_compare_runs PRIVATE
  TISSUE_COMPARE_TEST_DIR="${CMAKE_CURRENT_LIST_DIR}/compare"
  TISSUE_FMU_DIR="${CMAKE_BINARY_DIR}/fmus"
  TISSUE_HOST_EXECUTABLE="$<TARGET_FILE:tissue-host>"
  TISSUE_MPIEXEC="${MPIEXEC_EXECUTABLE}")
find_package(MPI COMPONENTS C QUIET)  # as host/compare/compare.cmake: did tissue-host get MPI?
if(MPI_C_FOUND)
  target_compile_definitions(test_host_compare_runs PRIVATE TISSUE_HOST_HAS_MPI=1)
endif()
add_dependencies(test_host_compare_runs tissue-host tissue_fmu_package hapticloop_fmu_package)
gtest_discover_tests(test_host_compare_runs PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60 TIMEOUT 600)
