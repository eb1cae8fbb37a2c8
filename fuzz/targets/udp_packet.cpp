// Door: a UDP datagram to the device bridge (device/udp_packet.hpp, what UdpDevice calls on each
// datagram). Promise: refused with a named DecodeError, or a pose packet with a finite position, a
// non-zero quaternion and a sequence from 1, that encodes to the same bytes; the same for a force
// packet (what a driver decodes).
#include "device/udp_packet.hpp"
#include "support/promise.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <span>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue::host::udp;
  const std::span<const std::uint8_t> datagram(data, size);
  PosePacket pose;
  const DecodeError pose_error = decode_pose(datagram, pose);
  if (pose_error != DecodeError::none) {
    tissue::fuzz::require_message(decode_error_name(pose_error), "udp pose");
  } else {
    if (pose.sequence == 0) tissue::fuzz::broken("udp pose accepted with sequence 0");
    for (const double x : pose.pose.position_m) {
      if (!std::isfinite(x)) tissue::fuzz::broken("udp pose accepted with a non-finite position");
    }
    const auto again = encode_pose(pose);
    if (size != again.size() || !std::equal(again.begin(), again.end(), data))
      tissue::fuzz::broken("an accepted pose packet does not encode to the same bytes");
  }
  ForcePacket force;
  const DecodeError force_error = decode_force(datagram, force);
  if (force_error != DecodeError::none) {
    tissue::fuzz::require_message(decode_error_name(force_error), "udp force");
  } else {
    for (const double f : force.force_n) {
      if (!std::isfinite(f)) tissue::fuzz::broken("udp force accepted with a non-finite force");
    }
  }
  return 0;
}
