# test_fmu_description: modelDescription/Tissue.xml validates against the FMI 3.0 schema and equals
# the variable table in fmu_src/fmi3/variables.cpp. Needs neither the core nor the built FMU.
find_package(pugixml REQUIRED)

add_executable(test_fmu_description ${CMAKE_CURRENT_LIST_DIR}/test_model_description.cpp)
target_link_libraries(test_fmu_description PRIVATE tissue::fmi3_variables pugixml::pugixml GTest::gtest
                                                   GTest::gtest_main tissue::warnings)
target_compile_definitions(test_fmu_description
  PRIVATE TISSUE_MODEL_DESCRIPTION_XML="${PROJECT_SOURCE_DIR}/modelDescription/Tissue.xml"
          TISSUE_FMI3_SCHEMA_DIR="${PROJECT_SOURCE_DIR}/../shared/fmi/schema/fmi3")
gtest_discover_tests(test_fmu_description PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)
