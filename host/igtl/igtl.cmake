# tissue::host_igtl - OpenIGTLink for tissue-host (OPENIGTLINK.md): a TCP server on its own thread,
# the device that takes the tool pose from it and sends the force back, and the POLYDATA surface
# stream. Messages are packed and unpacked by Debian's libopenigtlink (1.11). Included from
# host/CMakeLists.txt after device/, output/ and sync/.
find_path(OPENIGTLINK_INCLUDE_DIR igtlMessageHeader.h PATH_SUFFIXES openigtlink REQUIRED)
find_library(OPENIGTLINK_LIBRARY OpenIGTLink REQUIRED)
add_library(tissue_openigtlink INTERFACE IMPORTED GLOBAL)
target_include_directories(tissue_openigtlink SYSTEM INTERFACE ${OPENIGTLINK_INCLUDE_DIR})
target_link_libraries(tissue_openigtlink INTERFACE ${OPENIGTLINK_LIBRARY})

add_library(tissue_host_igtl STATIC
  ${CMAKE_CURRENT_LIST_DIR}/igtl_codec.cpp
  ${CMAKE_CURRENT_LIST_DIR}/igtl_server.cpp
  ${CMAKE_CURRENT_LIST_DIR}/igtl_device.cpp)
add_library(tissue::host_igtl ALIAS tissue_host_igtl)
# Headers are included as "igtl/<file>.hpp"; the library's own headers stay private.
target_include_directories(tissue_host_igtl PUBLIC ${PROJECT_SOURCE_DIR}/host)
target_compile_features(tissue_host_igtl PUBLIC cxx_std_20)
target_link_libraries(tissue_host_igtl PUBLIC tissue::host_device tissue::host_output tissue::host_sync
                      PRIVATE tissue_openigtlink Eigen3::Eigen tissue::warnings)
