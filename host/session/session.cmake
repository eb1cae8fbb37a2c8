# tissue::host_session - a session of tissue-host: the scenario's device, the two FMU links and the
# tissue sample's relay, the recording (frames, log, summary) and the live view, handed to a
# scheduler (schedule/: haptic and dynamics threads, offline mode). Included from
# host/CMakeLists.txt; links no part of the FMUs.
add_library(tissue_host_session STATIC ${CMAKE_CURRENT_LIST_DIR}/session.cpp ${CMAKE_CURRENT_LIST_DIR}/session_device.cpp)
add_library(tissue::host_session ALIAS tissue_host_session)
target_include_directories(tissue_host_session PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_session PUBLIC cxx_std_20)
target_link_libraries(tissue_host_session
  PUBLIC tissue::fmi_importer tissue::host_scenario tissue::host_device tissue::host_links tissue::host_output
         tissue::host_sync tissue::host_view tissue::host_schedule tissue::host_igtl Threads::Threads
  PRIVATE tissue::warnings)

