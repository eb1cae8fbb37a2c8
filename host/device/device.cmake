# tissue::host_device - the haptic devices of tissue-host behind one interface (device.hpp): scripted
# (waypoints), a simulated hand holding them (hand_device.hpp), replay (a recorded CSV) and the UDP
# bridge to a driver process (UDP_PROTOCOL.md). Included from host/CMakeLists.txt. Plain
# C++ and POSIX sockets: no FMI, no tissue::core.
add_library(tissue_host_device STATIC
  ${CMAKE_CURRENT_LIST_DIR}/scripted_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/replay_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/force_watchdog.cpp
  ${CMAKE_CURRENT_LIST_DIR}/socket_address.cpp
  ${CMAKE_CURRENT_LIST_DIR}/udp_packet.cpp
  ${CMAKE_CURRENT_LIST_DIR}/udp_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/simulated_hand.cpp
  ${CMAKE_CURRENT_LIST_DIR}/hand_device.cpp)
add_library(tissue::host_device ALIAS tissue_host_device)
# Headers are included as "device/<file>.hpp".
target_include_directories(tissue_host_device PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_device PUBLIC cxx_std_20)
# Eigen (header only) for the hand's matrix exponential.
target_link_libraries(tissue_host_device PUBLIC tissue::ports PRIVATE Eigen3::Eigen tissue::warnings)
