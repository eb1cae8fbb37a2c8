# Tests of tissue::host_output (label "host"): the VTU and PVD documents parsed back with
# pugixml, the PNG renders measured against analytic projected areas and decoded with libpng.
if(NOT TARGET tissue::host_output)
  return()
endif()
find_package(PNG REQUIRED)
find_package(pugixml REQUIRED)
if(TARGET pugixml::pugixml)
  set(TISSUE_OUTPUT_TEST_PUGIXML pugixml::pugixml)
else()
  set(TISSUE_OUTPUT_TEST_PUGIXML pugixml)
endif()

add_executable(test_host_output ${CMAKE_CURRENT_LIST_DIR}/test_output.cpp)
find_package(nlohmann_json REQUIRED)
target_link_libraries(test_host_output PRIVATE tissue::host_output PNG::PNG ${TISSUE_OUTPUT_TEST_PUGIXML} nlohmann_json::nlohmann_json
                                               GTest::gtest GTest::gtest_main tissue::warnings)
target_include_directories(test_host_output PRIVATE ${PROJECT_SOURCE_DIR}/tests)  # host/vtu_read.hpp
gtest_discover_tests(test_host_output PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)
