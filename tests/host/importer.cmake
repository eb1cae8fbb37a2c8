# Tests of the FMI importer (label "host"). They never link tissue::core: the host only loads FMUs.

# fmi3_abi.h compiled as C, with C warning flags (tissue::warnings carries C++-only ones).
add_library(tissue_host_abi_c OBJECT ${CMAKE_CURRENT_LIST_DIR}/abi_compiles.c)
set_target_properties(tissue_host_abi_c PROPERTIES C_STANDARD 11 C_STANDARD_REQUIRED ON C_EXTENSIONS OFF)
target_link_libraries(tissue_host_abi_c PRIVATE tissue::fmi3_abi)
target_compile_options(tissue_host_abi_c PRIVATE -Wall -Wextra -Wpedantic $<$<BOOL:${TISSUE_WERROR}>:-Werror>)

# A shared library exporting only two FMI functions (not an FMU), for the missing-function refusal.
add_library(tissue_host_partial_fmi3 MODULE ${CMAKE_CURRENT_LIST_DIR}/partial_fmi3_binary.c)
set_target_properties(tissue_host_partial_fmi3 PROPERTIES C_STANDARD 11 C_VISIBILITY_PRESET hidden PREFIX "")
target_link_libraries(tissue_host_partial_fmi3 PRIVATE tissue::fmi3_abi)
target_compile_options(tissue_host_partial_fmi3 PRIVATE -Wall -Wextra -Wpedantic $<$<BOOL:${TISSUE_WERROR}>:-Werror>)

# An archive packed the way the FMU is (cmake -E tar --format=zip), holding the Tissue model
# description and no binary: FmuArchive must read what our own packing produces.
set(TISSUE_HOST_CMAKE_PACKED_FMU ${CMAKE_CURRENT_BINARY_DIR}/cmake_packed.fmu)
add_custom_command(OUTPUT ${TISSUE_HOST_CMAKE_PACKED_FMU}
  COMMAND ${CMAKE_COMMAND} -E rm -rf cmake_packed ${TISSUE_HOST_CMAKE_PACKED_FMU}
  COMMAND ${CMAKE_COMMAND} -E make_directory cmake_packed/resources cmake_packed/binaries/x86_64-linux
  COMMAND ${CMAKE_COMMAND} -E copy ${TISSUE_TISSUE_XML_PATH} cmake_packed/modelDescription.xml
  COMMAND ${CMAKE_COMMAND} -E copy ${PROJECT_SOURCE_DIR}/libports/README.md cmake_packed/resources/README.md
  COMMAND ${CMAKE_COMMAND} -E chdir cmake_packed
          ${CMAKE_COMMAND} -E tar cf ${TISSUE_HOST_CMAKE_PACKED_FMU} --format=zip modelDescription.xml resources binaries
  DEPENDS ${TISSUE_TISSUE_XML_PATH} ${PROJECT_SOURCE_DIR}/libports/README.md
  WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}
  COMMENT "Packing cmake_packed.fmu for the host tests"
  VERBATIM)
add_custom_target(tissue_host_cmake_packed_fmu DEPENDS ${TISSUE_HOST_CMAKE_PACKED_FMU})
add_dependencies(tissue_host_cmake_packed_fmu tissue_fmu_package)

add_executable(test_host_importer
  ${CMAKE_CURRENT_LIST_DIR}/test_model_description.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_fmu_archive.cpp
  ${CMAKE_CURRENT_LIST_DIR}/test_fmu3_library.cpp
  $<TARGET_OBJECTS:tissue_host_abi_c>)
target_include_directories(test_host_importer PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(test_host_importer PRIVATE tissue::fmi_importer PkgConfig::TISSUE_LIBZIP
                                                 GTest::gtest GTest::gtest_main tissue::warnings)
target_compile_definitions(test_host_importer PRIVATE
  TISSUE_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
  TISSUE_TISSUE_XML="${TISSUE_TISSUE_XML_PATH}"
  TISSUE_PARTIAL_FMI3_BINARY="$<TARGET_FILE:tissue_host_partial_fmi3>"
  TISSUE_HOST_CMAKE_PACKED_FMU="${TISSUE_HOST_CMAKE_PACKED_FMU}")
add_dependencies(test_host_importer tissue_host_partial_fmi3 tissue_host_cmake_packed_fmu)
gtest_discover_tests(test_host_importer PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)
