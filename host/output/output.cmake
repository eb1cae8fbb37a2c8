# tissue::host_output - what a session records: VTU frames and a PVD index for ParaView, a headless
# PNG render of the surface (libpng), the tick log and the device recording, the real-time slots'
# timings, and the summary.
# Included from host/CMakeLists.txt; of the project it knows only the devices' pose type.
find_package(PNG REQUIRED)
find_package(nlohmann_json REQUIRED)

add_library(tissue_host_output STATIC
  ${CMAKE_CURRENT_LIST_DIR}/vtu_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/pvd_writer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/png_renderer.cpp
  ${CMAKE_CURRENT_LIST_DIR}/session_log.cpp
  ${CMAKE_CURRENT_LIST_DIR}/session_summary.cpp
  ${CMAKE_CURRENT_LIST_DIR}/slot_timing.cpp)
add_library(tissue::host_output ALIAS tissue_host_output)
# Headers are included as "output/<file>.hpp".
target_include_directories(tissue_host_output PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_output PUBLIC cxx_std_20)
target_link_libraries(tissue_host_output PUBLIC tissue::host_device nlohmann_json::nlohmann_json PRIVATE PNG::PNG tissue::warnings)
