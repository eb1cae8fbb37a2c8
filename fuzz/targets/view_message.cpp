// Door: a text message from a page of the live view (host/view: the browser device reads each
// WebSocket text message of at most MAX_VIEW_MESSAGE_BYTES with parse_pose_message). Promise: never
// throws; refused with a reason, or a pose with a finite position and a unit quaternion.
#include "view/pose_message.hpp"
#include "support/promise.hpp"

#include <cmath>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue::host;
  if (size > MAX_VIEW_MESSAGE_BYTES) return 0;  // dropped unread by the server (view_server.cpp)
  std::string why;
  const auto message = parse_pose_message(tissue::fuzz::as_text(data, size), &why);
  if (!message) {
    tissue::fuzz::require_message(why, "view message");
    return 0;
  }
  const auto& pose = message->pose;
  double norm_squared = 0.0;
  for (const double q : pose.orientation_wxyz) norm_squared += q * q;
  for (const double x : pose.position_m) {
    if (!std::isfinite(x)) tissue::fuzz::broken("a view pose accepted with a non-finite position");
  }
  if (!(std::abs(norm_squared - 1.0) < 1e-9)) tissue::fuzz::broken("a view pose accepted without a unit quaternion");
  return 0;
}
