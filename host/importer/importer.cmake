# tissue::fmi_importer - loads FMI 3.0 Co-Simulation FMUs: unzip (libzip), parse
# modelDescription.xml (pugixml), dlopen the binary, and run instances. Included from
# host/CMakeLists.txt; links neither tissue::core nor anything else of the FMU.
find_package(PkgConfig REQUIRED)
pkg_check_modules(TISSUE_LIBZIP REQUIRED IMPORTED_TARGET GLOBAL libzip)
find_package(pugixml REQUIRED)
if(TARGET pugixml::pugixml)
  set(TISSUE_PUGIXML_TARGET pugixml::pugixml)
else()
  set(TISSUE_PUGIXML_TARGET pugixml)
endif()

add_library(tissue_fmi_importer STATIC
  ${CMAKE_CURRENT_LIST_DIR}/fmu_archive.cpp
  ${CMAKE_CURRENT_LIST_DIR}/model_description.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fmu3_library.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fmu3.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fmu3_instance.cpp)
add_library(tissue::fmi_importer ALIAS tissue_fmi_importer)
# Headers are included as "importer/<file>.hpp".
get_filename_component(TISSUE_HOST_INCLUDE_DIR "${CMAKE_CURRENT_LIST_DIR}" DIRECTORY)
target_include_directories(tissue_fmi_importer PUBLIC $<BUILD_INTERFACE:${TISSUE_HOST_INCLUDE_DIR}>
                                                      $<INSTALL_INTERFACE:${TISSUE_INSTALL_INCLUDEDIR}>)
target_compile_features(tissue_fmi_importer PUBLIC cxx_std_20)
target_link_libraries(tissue_fmi_importer
  PUBLIC tissue::fmi3_abi
  PRIVATE PkgConfig::TISSUE_LIBZIP ${TISSUE_PUGIXML_TARGET} ${CMAKE_DL_LIBS} tissue::warnings)
