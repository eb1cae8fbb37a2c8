# What `cmake --install` puts where (issue 43; docs/INSTALL.md), and the Debian package (packaging.cmake).
# Included last by the top-level CMakeLists.txt, when every target exists. Two components:
#   runtime - tissue-host and the benches (bin/), the FMUs, the SSP, the meshes, the scenarios and the
#             live view's page (share/tissue/), the Python module (TISSUE_PYTHON_INSTALL_DIR);
#   dev     - the core's, the haptic core's and the FMI importer's headers (include/tissue/) and static
#             libraries (lib/), with the CMake package Tissue (lib/cmake/Tissue: tissue::core, ...).
# The folders themselves (TISSUE_INSTALL_*) are set once, in the top-level CMakeLists.txt.
include(CMakePackageConfigHelpers)
# `make install` and cpack take what was built and never start a build (the suite runs them beside
# other tests; build first).
set(CMAKE_SKIP_INSTALL_ALL_DEPENDENCY ON)

# -- runtime: the programs, the FMUs, the data ---------------------------------------------------
install(TARGETS tissue-host tissue-bench tissue-cut-bench tissue-convergence tissue-demo
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
install(FILES ${TISSUE_TISSUE_FMU_PATH} ${TISSUE_HAPTICLOOP_FMU_PATH} DESTINATION ${TISSUE_INSTALL_DATADIR}/fmus
        COMPONENT runtime)
install(FILES ${TISSUE_TISSUE_FMI2_FMU_PATH} ${TISSUE_HAPTICLOOP_FMI2_FMU_PATH}
        DESTINATION ${TISSUE_INSTALL_DATADIR}/fmus/fmi2 COMPONENT runtime)
install(FILES ${TISSUE_SSP_PATH} DESTINATION ${TISSUE_INSTALL_DATADIR}/ssp COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/meshes/ DESTINATION ${TISSUE_INSTALL_DATADIR}/meshes COMPONENT runtime
        FILES_MATCHING PATTERN "*.veg" PATTERN "*.bou" PATTERN "*.obj" PATTERN "*.msh" PATTERN "*.geo"
                       PATTERN "*.py" PATTERN "README.md")
if(NOT IS_DIRECTORY "${TISSUE_VIEW_DIR}")
  message(FATAL_ERROR "install.cmake: TISSUE_VIEW_DIR (${TISSUE_VIEW_DIR}) is not the view's folder")
endif()
install(DIRECTORY ${TISSUE_VIEW_DIR}/ DESTINATION ${TISSUE_INSTALL_DATADIR}/view COMPONENT runtime)

# The scenarios name their meshes relative to themselves (host/scenarios -> ../../meshes); installed,
# the meshes sit beside them (share/tissue/scenarios -> ../meshes). The build writes the installed
# copies with that one path rewritten, so that the repository's files stay the ones that are tested.
file(GLOB TISSUE_SCENARIO_FILES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/host/scenarios/*.toml)
set(TISSUE_INSTALLED_SCENARIO_DIR ${CMAKE_BINARY_DIR}/installed_scenarios)
file(MAKE_DIRECTORY ${TISSUE_INSTALLED_SCENARIO_DIR})
foreach(scenario ${TISSUE_SCENARIO_FILES})
  get_filename_component(name ${scenario} NAME)
  file(READ ${scenario} text)
  string(REPLACE "\"../../meshes/" "\"../meshes/" text "${text}")
  file(WRITE ${CMAKE_BINARY_DIR}/CMakeFiles/scenario.tmp "${text}")
  file(COPY_FILE ${CMAKE_BINARY_DIR}/CMakeFiles/scenario.tmp ${TISSUE_INSTALLED_SCENARIO_DIR}/${name} ONLY_IF_DIFFERENT)
  install(FILES ${TISSUE_INSTALLED_SCENARIO_DIR}/${name} DESTINATION ${TISSUE_INSTALL_DATADIR}/scenarios
          COMPONENT runtime)
endforeach()

if(TARGET tissue_python)
  set(python_dir ${TISSUE_PYTHON_INSTALL_DIR})
  if(NOT python_dir)
    set(python_dir lib/python3.${TISSUE_PYTHON_MINOR_VERSION}/dist-packages)
  endif()
  install(TARGETS tissue_python LIBRARY DESTINATION ${python_dir} COMPONENT runtime)
endif()

# -- dev: headers, static libraries, the CMake package ---------------------------------------------
set(TISSUE_EXPORTED_TARGETS
    # target               exported as
    tissue_core            core
    tissue_haptic_core     haptic_core
    tissue_fmi_importer    fmi_importer
    tissue_ports           ports
    tissue_serial          serial
    tissue_fmi3_abi        fmi3_abi
    tissue_bullet          bullet
    tissue_warnings        warnings)
set(exported)
while(TISSUE_EXPORTED_TARGETS)
  list(POP_FRONT TISSUE_EXPORTED_TARGETS target name)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  list(APPEND exported ${target})
endwhile()
install(TARGETS ${exported} EXPORT TissueTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)

foreach(folder libtissue/core libtissue/serial libtissue/haptic libports/ports host/importer)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${folder} DESTINATION ${TISSUE_INSTALL_INCLUDEDIR} COMPONENT dev
          FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
endforeach()
install(FILES ${PROJECT_SOURCE_DIR}/fmu_src/fmi3/abi/fmi3_abi.h ${PROJECT_SOURCE_DIR}/fmu_src/fmi3/abi/fmi3_function_names.hpp
        DESTINATION ${TISSUE_INSTALL_INCLUDEDIR} COMPONENT dev)

install(EXPORT TissueTargets NAMESPACE tissue:: DESTINATION ${TISSUE_INSTALL_CMAKEDIR} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/TissueConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/package/TissueConfig.cmake
                              INSTALL_DESTINATION ${TISSUE_INSTALL_CMAKEDIR}
                              PATH_VARS TISSUE_INSTALL_DATADIR)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/package/TissueConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/package/TissueConfig.cmake ${CMAKE_BINARY_DIR}/package/TissueConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindCHOLMOD.cmake
        DESTINATION ${TISSUE_INSTALL_CMAKEDIR} COMPONENT dev)
