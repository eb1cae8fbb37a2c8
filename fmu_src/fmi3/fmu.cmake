# Tissue.so (the FMI 3.0 C ABI over the core) and build/<preset>/fmus/Tissue.fmu: modelDescription.xml,
# binaries/x86_64-linux/Tissue.so, resources/frog.veg, zipped by CMake as Reference-FMUs does.
add_library(tissue_fmu SHARED ${CMAKE_CURRENT_LIST_DIR}/fmi3_functions.cpp ${CMAKE_CURRENT_LIST_DIR}/tissue_instance.cpp)
set_target_properties(tissue_fmu PROPERTIES OUTPUT_NAME Tissue PREFIX "" CXX_VISIBILITY_PRESET hidden
                                            C_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
target_include_directories(tissue_fmu PRIVATE ${PROJECT_SOURCE_DIR}/fmu_src)
target_link_libraries(tissue_fmu PRIVATE tissue::core tissue::resources tissue::fmi3_variables tissue::fmi3_abi
                                         tissue::warnings)
# Only the fmi3* functions leave the library: the static core's symbols stay inside, and nothing is
# left undefined for the importer to resolve.
target_link_options(tissue_fmu PRIVATE -Wl,--exclude-libs,ALL -Wl,--no-undefined)

set(TISSUE_FMU_STAGE ${CMAKE_BINARY_DIR}/fmus/Tissue)
set(TISSUE_FMU ${CMAKE_BINARY_DIR}/fmus/Tissue.fmu)
add_custom_command(
  OUTPUT ${TISSUE_FMU}
  COMMAND ${CMAKE_COMMAND} -E rm -rf ${TISSUE_FMU_STAGE}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${TISSUE_FMU_STAGE}/binaries/x86_64-linux ${TISSUE_FMU_STAGE}/resources
  COMMAND ${CMAKE_COMMAND} -E copy ${PROJECT_SOURCE_DIR}/modelDescription/Tissue.xml ${TISSUE_FMU_STAGE}/modelDescription.xml
  COMMAND ${CMAKE_COMMAND} -E copy $<TARGET_FILE:tissue_fmu> ${TISSUE_FMU_STAGE}/binaries/x86_64-linux/Tissue.so
  COMMAND ${CMAKE_COMMAND} -E copy ${PROJECT_SOURCE_DIR}/meshes/frog.veg ${TISSUE_FMU_STAGE}/resources/frog.veg
  COMMAND ${CMAKE_COMMAND} -E rm -f ${TISSUE_FMU}
  COMMAND ${CMAKE_COMMAND} -E chdir ${TISSUE_FMU_STAGE} ${CMAKE_COMMAND} -E tar cf ${TISSUE_FMU} --format=zip
          modelDescription.xml binaries resources
  DEPENDS tissue_fmu ${PROJECT_SOURCE_DIR}/modelDescription/Tissue.xml ${PROJECT_SOURCE_DIR}/meshes/frog.veg
  COMMENT "Packaging ${TISSUE_FMU}"
  VERBATIM)
add_custom_target(tissue_fmu_package ALL DEPENDS ${TISSUE_FMU})
set(TISSUE_FMU_PATH ${TISSUE_FMU} CACHE INTERNAL "The packaged Tissue FMU")
