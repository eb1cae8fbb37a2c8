# tissue::host_compare - tissue-host compare: integrator settings run offline through the session
# against a reference, metrics, compare.csv, the error-against-cost PNG, recommendations, and the
# runs dealt over threads (and, in tissue-host, over MPI ranks: mpi_distribution.cpp is compiled
# into the executable only). Included from host/CMakeLists.txt; links no part of the FMUs.
find_package(tomlplusplus REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(TISSUE_CAIRO REQUIRED IMPORTED_TARGET cairo)
add_library(tissue_host_compare STATIC
  ${CMAKE_CURRENT_LIST_DIR}/compare_settings.cpp
  ${CMAKE_CURRENT_LIST_DIR}/compare_metrics.cpp
  ${CMAKE_CURRENT_LIST_DIR}/compare_run.cpp
  ${CMAKE_CURRENT_LIST_DIR}/compare_table.cpp
  ${CMAKE_CURRENT_LIST_DIR}/recommendation.cpp
  ${CMAKE_CURRENT_LIST_DIR}/plot_png.cpp
  ${CMAKE_CURRENT_LIST_DIR}/compare_report.cpp
  ${CMAKE_CURRENT_LIST_DIR}/compare.cpp)
add_library(tissue::host_compare ALIAS tissue_host_compare)
target_include_directories(tissue_host_compare PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_compare PUBLIC cxx_std_20)
target_link_libraries(tissue_host_compare
  PUBLIC tissue::host_session tissue::host_output Threads::Threads
  PRIVATE tomlplusplus::tomlplusplus nlohmann_json::nlohmann_json PkgConfig::TISSUE_CAIRO tissue::warnings)

# MPI for `mpirun -n N tissue-host compare`; tissue-host builds without it (one process only).
find_package(MPI COMPONENTS C)
if(MPI_C_FOUND)
  set(TISSUE_HOST_MPI_SOURCES ${CMAKE_CURRENT_LIST_DIR}/mpi_distribution.cpp)
else()
  message(STATUS "tissue-host: no MPI (libopenmpi-dev): compare runs in one process only")
endif()
