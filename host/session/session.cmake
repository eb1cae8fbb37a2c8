# tissue::host_session - what tissue-host runs: scenarios (toml++), the scripted and replay devices,
# the two FMU links over the importer, and the session (haptic and dynamics threads, offline mode,
# frames, log, summary). Included from host/CMakeLists.txt; links no part of the FMUs.
find_package(tomlplusplus REQUIRED)
add_library(tissue_host_session STATIC
  ${CMAKE_CURRENT_LIST_DIR}/../scenario/scenario.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../device/scripted_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/../device/replay_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/fmu_links.cpp
  ${CMAKE_CURRENT_LIST_DIR}/session.cpp)
add_library(tissue::host_session ALIAS tissue_host_session)
target_include_directories(tissue_host_session PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_session PUBLIC cxx_std_20)
target_link_libraries(tissue_host_session
  PUBLIC tissue::fmi_importer tissue::host_device tissue::host_output tissue::host_view Threads::Threads
  PRIVATE tomlplusplus::tomlplusplus tissue::warnings)

