// pose_message.hpp - the page's pose message (VIEW_PROTOCOL.md, "Page -> host") parsed and checked.
// Pure functions: no sockets, no threads; the browser device and the tests use them.
#pragma once

#include "device/device.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace tissue::host {

/// The largest text message the host reads from a page [bytes]; longer ones are dropped unread.
inline constexpr std::size_t MAX_VIEW_MESSAGE_BYTES = 512;
/// The most messages one page may send in a second; more are dropped (a flood).
inline constexpr int MAX_VIEW_MESSAGES_PER_S = 1000;

struct PoseMessage {
  std::uint64_t seq = 0;
  DevicePose pose;  ///< orientation normalized
};

/// Parses `{"type":"pose","seq":N,"position_m":[x,y,z],"orientation_wxyz":[w,x,y,z],"mode":"..."}`.
/// nullopt, with the reason in `why` when given, for anything else: not JSON, another type, a
/// missing or extra-long field, a number that is not finite, a zero quaternion, an unknown mode,
/// a seq that is not a non-negative integer. Never throws.
std::optional<PoseMessage> parse_pose_message(std::string_view text, std::string* why = nullptr);

}  // namespace tissue::host
