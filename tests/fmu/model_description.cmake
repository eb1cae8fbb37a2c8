# test_<fmu>_description: an FMU's modelDescription XML validates against the FMI 3.0 schema and
# equals its variable table in code. Needs neither the core nor the built FMU.
find_package(pugixml REQUIRED)

# tissue_add_description_test(<name> XML <file> HEADER <header> DESCRIPTION <function> LIBRARY <target>)
function(tissue_add_description_test name)
  cmake_parse_arguments(ARG "" "XML;HEADER;DESCRIPTION;LIBRARY" "" ${ARGN})
  add_executable(${name} ${CMAKE_CURRENT_LIST_DIR}/test_model_description.cpp)
  target_link_libraries(${name} PRIVATE ${ARG_LIBRARY} pugixml::pugixml GTest::gtest GTest::gtest_main
                                        tissue::warnings)
  target_compile_definitions(${name}
    PRIVATE TISSUE_MODEL_DESCRIPTION_XML="${ARG_XML}" TISSUE_FMU_VARIABLES_HEADER="${ARG_HEADER}"
            TISSUE_FMU_DESCRIPTION=${ARG_DESCRIPTION} TISSUE_FMI3_SCHEMA_DIR="${PROJECT_SOURCE_DIR}/../shared/fmi/schema/fmi3")
  gtest_discover_tests(${name} PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)
endfunction()

tissue_add_description_test(test_fmu_description XML ${PROJECT_SOURCE_DIR}/modelDescription/Tissue.xml
                            HEADER tissue_fmu/variables.hpp DESCRIPTION tissue::tissue_fmu::tissue_model_description
                            LIBRARY tissue::tissue_fmu_variables)
tissue_add_description_test(test_haptic_loop_description XML ${PROJECT_SOURCE_DIR}/modelDescription/HapticLoop.xml
                            HEADER haptic_loop/variables.hpp DESCRIPTION tissue::haptic_fmu::haptic_loop_model_description
                            LIBRARY tissue::haptic_loop_variables)
