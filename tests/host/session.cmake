# Sessions of tissue-host (label "host"): every scenario offline, reproducibility, record and
# replay, the real-time threads (the tsan preset's data-race check), scenario files refused.
if(NOT TARGET tissue::host_session)
  return()
endif()
add_executable(test_host_session ${CMAKE_CURRENT_LIST_DIR}/test_session.cpp)
find_package(nlohmann_json REQUIRED)
target_link_libraries(test_host_session PRIVATE tissue::host_session nlohmann_json::nlohmann_json GTest::gtest GTest::gtest_main
                                                tissue::warnings)
target_include_directories(test_host_session PRIVATE ${PROJECT_SOURCE_DIR}/tests)  # support/under_sanitizer.hpp
target_compile_definitions(test_host_session PRIVATE TISSUE_SCENARIO_DIR="${PROJECT_SOURCE_DIR}/host/scenarios"
                                                     TISSUE_FMU_DIR="${CMAKE_BINARY_DIR}/fmus")
add_dependencies(test_host_session tissue_fmu_package hapticloop_fmu_package)
gtest_discover_tests(test_host_session PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

# Palpation (issue 25): the palpation scenario's rendered force in its dwells against the full
# model's quasi-static pokes of the same body (the test builds the tissue as the FMU does).
add_executable(test_host_palpation ${CMAKE_CURRENT_LIST_DIR}/test_palpation.cpp)
target_include_directories(test_host_palpation PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_host_palpation PRIVATE tissue::host_session tissue_fmu_model GTest::gtest GTest::gtest_main
                                                  tissue::warnings)
target_compile_definitions(test_host_palpation PRIVATE TISSUE_SCENARIO_DIR="${PROJECT_SOURCE_DIR}/host/scenarios"
                                                       TISSUE_FMU_DIR="${CMAKE_BINARY_DIR}/fmus")
add_dependencies(test_host_palpation tissue_fmu_package hapticloop_fmu_package)
gtest_discover_tests(test_host_palpation PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60 TIMEOUT 900)

# The haptic thread allocates nothing (its own executable: it replaces operator new).
add_executable(test_host_session_allocations ${CMAKE_CURRENT_LIST_DIR}/test_session_allocations.cpp)
target_link_libraries(test_host_session_allocations PRIVATE tissue::host_session tissue_igtl_test_client GTest::gtest
                                                            GTest::gtest_main tissue::warnings)
target_compile_definitions(test_host_session_allocations
                           PRIVATE TISSUE_SCENARIO_DIR="${PROJECT_SOURCE_DIR}/host/scenarios"
                                   TISSUE_FMU_DIR="${CMAKE_BINARY_DIR}/fmus")
add_dependencies(test_host_session_allocations tissue_fmu_package hapticloop_fmu_package)
gtest_discover_tests(test_host_session_allocations PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

# The UDP device end to end through a real-time session, with the test sender as the driver.
add_executable(test_host_session_udp ${CMAKE_CURRENT_LIST_DIR}/test_session_udp.cpp ${CMAKE_CURRENT_LIST_DIR}/udp_sender.cpp)
target_include_directories(test_host_session_udp PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(test_host_session_udp PRIVATE tissue::host_session GTest::gtest GTest::gtest_main tissue::warnings)
target_compile_definitions(test_host_session_udp PRIVATE TISSUE_SCENARIO_DIR="${PROJECT_SOURCE_DIR}/host/scenarios"
                                                         TISSUE_FMU_DIR="${CMAKE_BINARY_DIR}/fmus")
add_dependencies(test_host_session_udp tissue_fmu_package hapticloop_fmu_package)
gtest_discover_tests(test_host_session_udp PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

# OpenIGTLink end to end through a real-time session, with the library-built client as the tracker.
add_executable(test_host_session_igtl ${CMAKE_CURRENT_LIST_DIR}/test_session_igtl.cpp)
target_include_directories(test_host_session_igtl PRIVATE ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_host_session_igtl PRIVATE tissue::host_session tissue_igtl_test_client GTest::gtest
                                                     GTest::gtest_main tissue::warnings)
target_compile_definitions(test_host_session_igtl PRIVATE TISSUE_SCENARIO_DIR="${PROJECT_SOURCE_DIR}/host/scenarios"
                                                          TISSUE_FMU_DIR="${CMAKE_BINARY_DIR}/fmus")
add_dependencies(test_host_session_igtl tissue_fmu_package hapticloop_fmu_package)
gtest_discover_tests(test_host_session_igtl PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

# docs/SLICER.md's runnable example: tissue-host and tissue-igtl-client on loopback port 18944.
add_test(NAME SlicerHowTo.TissueHostAndAnOpenIgtlinkClient
         COMMAND ${CMAKE_CURRENT_LIST_DIR}/slicer_howto.sh $<TARGET_FILE:tissue-host> $<TARGET_FILE:tissue-igtl-client>
                 ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_BINARY_DIR}/slicer_howto)
set_tests_properties(SlicerHowTo.TissueHostAndAnOpenIgtlinkClient PROPERTIES LABELS "host" TIMEOUT 60)
