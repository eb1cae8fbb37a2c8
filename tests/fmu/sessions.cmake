# Sessions on the built Tissue.fmu through the host's importer (never linking the core).
add_executable(test_fmu_sessions ${CMAKE_CURRENT_LIST_DIR}/test_fmu_sessions.cpp)
target_link_libraries(test_fmu_sessions PRIVATE tissue::fmi_importer tissue::warnings GTest::gtest GTest::gtest_main)
target_compile_definitions(test_fmu_sessions PRIVATE TISSUE_FMU_PATH="${TISSUE_FMU_PATH}")
add_dependencies(test_fmu_sessions tissue_fmu_package)
gtest_discover_tests(test_fmu_sessions PROPERTIES LABELS "fmu" DISCOVERY_TIMEOUT 60)
