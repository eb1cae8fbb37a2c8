# tissue::host_links - the host's two FMU instances as a session uses them (fmu_links.hpp) and the
# relay of the tissue sample between them (sample_relay.hpp), over the importer; the sample's fields
# come from tissue::ports. Included from host/CMakeLists.txt; links no part of the FMUs.
add_library(tissue_host_links STATIC ${CMAKE_CURRENT_LIST_DIR}/fmu_links.cpp ${CMAKE_CURRENT_LIST_DIR}/sample_relay.cpp)
add_library(tissue::host_links ALIAS tissue_host_links)
target_include_directories(tissue_host_links PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_links PUBLIC cxx_std_20)
target_link_libraries(tissue_host_links
  PUBLIC tissue::fmi_importer tissue::host_device tissue::host_output tissue::host_scenario tissue::ports
  PRIVATE tissue::warnings)
