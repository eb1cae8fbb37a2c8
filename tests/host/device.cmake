# Tests of host/device/ (label "host"): the UDP packet format and UdpDevice over loopback, with
# the driver-side UdpSender; and tissue-udp-sender, a scripted driver built on the same class.
add_executable(test_udp_device
  ${CMAKE_CURRENT_LIST_DIR}/test_udp_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/udp_sender.cpp)
target_include_directories(test_udp_device PRIVATE ${CMAKE_CURRENT_LIST_DIR} ${PROJECT_SOURCE_DIR}/tests)
target_link_libraries(test_udp_device PRIVATE tissue::host_device GTest::gtest GTest::gtest_main tissue::warnings)
gtest_discover_tests(test_udp_device PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

add_executable(tissue-udp-sender
  ${CMAKE_CURRENT_LIST_DIR}/udp_sender_main.cpp
  ${CMAKE_CURRENT_LIST_DIR}/udp_sender.cpp)
target_include_directories(tissue-udp-sender PRIVATE ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(tissue-udp-sender PRIVATE tissue::host_device tissue::warnings)

# The live view's pieces (pose messages, frames, the browser device) without a browser.
add_executable(test_view ${CMAKE_CURRENT_LIST_DIR}/test_view.cpp)
target_link_libraries(test_view PRIVATE tissue::host_view GTest::gtest GTest::gtest_main tissue::warnings)
gtest_discover_tests(test_view PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

# The simulated hand and its device (closed forms of the tick, the figures).
add_executable(test_simulated_hand ${CMAKE_CURRENT_LIST_DIR}/test_simulated_hand.cpp)
target_link_libraries(test_simulated_hand PRIVATE tissue::host_device GTest::gtest GTest::gtest_main tissue::warnings)
target_include_directories(test_simulated_hand PRIVATE ${PROJECT_SOURCE_DIR}/tests)
gtest_discover_tests(test_simulated_hand PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)

# OpenIGTLink (host/igtl/): messages, server and device over loopback with a client built on the
# same Debian library; and tissue-igtl-client, a scripted client for trying a session by hand.
add_library(tissue_igtl_test_client STATIC ${CMAKE_CURRENT_LIST_DIR}/igtl_client.cpp)
target_include_directories(tissue_igtl_test_client PUBLIC ${CMAKE_CURRENT_LIST_DIR})
target_link_libraries(tissue_igtl_test_client PUBLIC tissue::host_device PRIVATE tissue_openigtlink tissue::warnings)
add_executable(test_igtl ${CMAKE_CURRENT_LIST_DIR}/test_igtl.cpp)
target_link_libraries(test_igtl PRIVATE tissue::host_igtl tissue_igtl_test_client tissue_openigtlink GTest::gtest
                      GTest::gtest_main tissue::warnings)
gtest_discover_tests(test_igtl PROPERTIES LABELS "host" DISCOVERY_TIMEOUT 60)
add_executable(tissue-igtl-client ${CMAKE_CURRENT_LIST_DIR}/igtl_client_main.cpp)
target_link_libraries(tissue-igtl-client PRIVATE tissue_igtl_test_client tissue::warnings)
