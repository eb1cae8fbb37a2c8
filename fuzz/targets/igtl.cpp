// Door: an OpenIGTLink message on tissue-host's TCP server (host/igtl: the server reads the 58-byte
// header, drops a body over its limit unread, then decodes the whole message with
// Codec::decode_pose). Promise: never throws; a pose only with a finite position [m], a unit
// quaternion and a tool mode; anything else ignored or malformed.
#include "igtl/igtl_codec.hpp"
#include "igtl/igtl_server.hpp"
#include "support/promise.hpp"

#include <span>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue::host;
  static igtl_link::Codec codec{igtl_link::CodecSettings{}};
  if (size < igtl_link::HEADER_SIZE) return 0;  // the server waits for the rest
  const igtl_link::Header header =
      igtl_link::read_header(std::span<const std::uint8_t, igtl_link::HEADER_SIZE>(data, igtl_link::HEADER_SIZE));
  if (header.body_size > IgtlServerSettings{}.max_body_bytes) return 0;  // oversized: dropped unread
  const std::size_t message_size = igtl_link::HEADER_SIZE + static_cast<std::size_t>(header.body_size);
  if (size < message_size) return 0;  // the server waits for the rest
  DevicePose pose;
  const igtl_link::Verdict verdict = codec.decode_pose(header, std::span<const std::uint8_t>(data, message_size), pose);
  if (verdict != igtl_link::Verdict::pose) return 0;
  tissue::fuzz::require_usable_pose(pose, 1e-6, "igtl");  // the quaternion comes from a float matrix
  if (pose.mode == tissue::ToolMode::none) tissue::fuzz::broken("an igtl pose accepted without a tool mode");
  return 0;
}
