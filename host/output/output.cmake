# tissue::host_output - the host's picture outputs: VTU frames and a PVD index for ParaView, and
# a headless PNG render of the surface (libpng). Included from host/CMakeLists.txt; depends on
# nothing else of the project (it takes plain arrays, see surface_frame.hpp).
find_package(PNG REQUIRED)

add_library(tissue_host_output STATIC
  ${CMAKE_CURRENT_LIST_DIR}/vtu_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/pvd_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/png_renderer.cpp)
add_library(tissue::host_output ALIAS tissue_host_output)
# Headers are included as "output/<file>.hpp".
target_include_directories(tissue_host_output PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_output PUBLIC cxx_std_20)
target_link_libraries(tissue_host_output PRIVATE PNG::PNG tissue::warnings)
