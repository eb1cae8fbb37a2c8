# test_<fmu>_description: the modelDescription.xml the build wrote from an FMU's port schema
# validates against the FMI 3.0 schema and reads back as the table it was written from. Needs
# neither the core nor the built FMU, only the written XML.
find_package(pugixml REQUIRED)

# tissue_add_description_test(<name> XML <file> HEADER <header> DESCRIPTION <function> LIBRARY <target>)
function(tissue_add_description_test name)
  cmake_parse_arguments(ARG "" "XML;HEADER;DESCRIPTION;LIBRARY;WRITER" "" ${ARGN})
  add_executable(${name} ${CMAKE_CURRENT_LIST_DIR}/test_model_description.cpp)
  target_link_libraries(${name} PRIVATE ${ARG_LIBRARY} pugixml::pugixml GTest::gtest GTest::gtest_main
                                        tissue::warnings)
  add_dependencies(${name} ${ARG_WRITER})
  target_compile_definitions(${name}
    PRIVATE TISSUE_MODEL_DESCRIPTION_XML="${ARG_XML}" TISSUE_FMU_VARIABLES_HEADER="${ARG_HEADER}"
            TISSUE_FMU_DESCRIPTION=${ARG_DESCRIPTION} TISSUE_FMI3_SCHEMA_DIR="${PROJECT_SOURCE_DIR}/../shared/fmi/schema/fmi3")
  gtest_discover_tests(${name} PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)
endfunction()

tissue_add_description_test(test_fmu_description XML ${TISSUE_TISSUE_XML_PATH} WRITER tissue_fmu_package
                            HEADER tissue_fmu/variables.hpp DESCRIPTION tissue::tissue_fmu::tissue_model_description
                            LIBRARY tissue::tissue_fmu_variables)
tissue_add_description_test(test_haptic_loop_description XML ${TISSUE_HAPTICLOOP_XML_PATH} WRITER hapticloop_fmu_package
                            HEADER haptic_loop/variables.hpp DESCRIPTION tissue::haptic_fmu::haptic_loop_model_description
                            LIBRARY tissue::haptic_loop_variables)

# test_port_schema: the tissue sample's fields make both FMUs' entries, XMLs and the host's relay.
add_executable(test_port_schema ${CMAKE_CURRENT_LIST_DIR}/test_port_schema.cpp)
target_link_libraries(test_port_schema PRIVATE tissue::tissue_fmu_variables tissue::haptic_loop_variables
                                               tissue::host_links GTest::gtest GTest::gtest_main tissue::warnings)
gtest_discover_tests(test_port_schema PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)

# test_fmi3_checks: where the layer checks a set value (a counting model stands in for the FMUs').
add_executable(test_fmi3_checks ${CMAKE_CURRENT_LIST_DIR}/test_fmi3_checks.cpp)
target_link_libraries(test_fmi3_checks PRIVATE tissue::fmi3 GTest::gtest GTest::gtest_main tissue::warnings)
gtest_discover_tests(test_fmi3_checks PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)

# test_fmi2: the FMI 2.0 variants beside the 3.0 FMUs (both loaded with dlopen): the XML against
# the FMI 2.0 schema, the same outputs bit for bit, FMU states, element-wise sets, bad calls.
add_executable(test_fmi2 ${CMAKE_CURRENT_LIST_DIR}/test_fmi2.cpp)
target_link_libraries(test_fmi2 PRIVATE tissue::fmi2 tissue::ssp tissue::fmi2_abi tissue::fmi3_abi tissue::tissue_fmu_variables
                                        tissue::haptic_loop_variables GTest::gtest GTest::gtest_main ${CMAKE_DL_LIBS}
                                        tissue::warnings)
target_compile_definitions(test_fmi2 PRIVATE TISSUE_FMU_DIR="${CMAKE_BINARY_DIR}/fmus" TISSUE_SSP_DIR="${CMAKE_BINARY_DIR}/ssp"
                                             TISSUE_FMI2_SCHEMA_DIR="${PROJECT_SOURCE_DIR}/../shared/fmi/schema/fmi2")
add_dependencies(test_fmi2 tissue_fmu_package hapticloop_fmu_package tissue_fmi2_fmu_package hapticloop_fmi2_fmu_package
                 tissue_ssp_package)
gtest_discover_tests(test_fmi2 PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)

# The settings' tables in docs/FMU_VARIABLES.md and docs/PYTHON.md are the ones the schema gives
# (tissue-settings-doc docs rewrites them).
add_test(NAME SettingsDoc.TheDocsHoldTheSchemasTables COMMAND tissue-settings-doc ${PROJECT_SOURCE_DIR}/docs --check)
set_tests_properties(SettingsDoc.TheDocsHoldTheSchemasTables PROPERTIES LABELS "fmu")
