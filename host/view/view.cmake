# tissue::host_view - the live view of a session in the browser (issue 11, VIEW_PROTOCOL.md): the
# HTTP + WebSocket server (websocketpp on standalone asio, from Debian), the frame encoder, the
# pages' pose messages (nlohmann::json) and the browser device. Included from host/CMakeLists.txt.
find_package(nlohmann_json REQUIRED)
find_path(TISSUE_WEBSOCKETPP_INCLUDE websocketpp/server.hpp REQUIRED)
find_path(TISSUE_ASIO_INCLUDE asio.hpp REQUIRED)

# websocketpp 0.8.2 does not compile as C++20: the server is its own C++17 library, and its header
# exposes no websocketpp type.
add_library(tissue_host_view_server STATIC ${CMAKE_CURRENT_LIST_DIR}/view_server.cpp)
set_target_properties(tissue_host_view_server PROPERTIES CXX_STANDARD 17 CXX_STANDARD_REQUIRED ON)
target_include_directories(tissue_host_view_server PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_include_directories(tissue_host_view_server SYSTEM PRIVATE ${TISSUE_WEBSOCKETPP_INCLUDE} ${TISSUE_ASIO_INCLUDE})
target_compile_definitions(tissue_host_view_server PRIVATE ASIO_STANDALONE)
target_link_libraries(tissue_host_view_server PRIVATE Threads::Threads)

add_library(tissue_host_view STATIC
  ${CMAKE_CURRENT_LIST_DIR}/pose_message.cpp
  ${CMAKE_CURRENT_LIST_DIR}/view_frame.cpp
  ${CMAKE_CURRENT_LIST_DIR}/browser_device.cpp
  ${CMAKE_CURRENT_LIST_DIR}/live_view.cpp)
add_library(tissue::host_view ALIAS tissue_host_view)
target_include_directories(tissue_host_view PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_view PUBLIC cxx_std_20)
target_link_libraries(tissue_host_view
  PUBLIC tissue_host_view_server tissue::host_device tissue::host_output tissue::host_sync Threads::Threads
  PRIVATE nlohmann_json::nlohmann_json tissue::warnings)

# The page and three.js (npm, ./scripts/setup) are served from the build, never from the network.
set(TISSUE_VIEW_DIR ${CMAKE_BINARY_DIR}/view CACHE INTERNAL "The live view's page and three.js, as served and installed")
set(TISSUE_THREE_DIR ${PROJECT_SOURCE_DIR}/node_modules/three)
foreach(file index.html view.js)
  configure_file(${CMAKE_CURRENT_LIST_DIR}/web/${file} ${TISSUE_VIEW_DIR}/${file} COPYONLY)
endforeach()
if(EXISTS ${TISSUE_THREE_DIR}/build/three.module.js)
  configure_file(${TISSUE_THREE_DIR}/build/three.module.js ${TISSUE_VIEW_DIR}/three.module.js COPYONLY)
  configure_file(${TISSUE_THREE_DIR}/examples/jsm/controls/OrbitControls.js ${TISSUE_VIEW_DIR}/OrbitControls.js COPYONLY)
else()
  message(WARNING "three.js is not installed (node_modules/three): run ./scripts/setup; tissue-host --view will say so")
endif()
