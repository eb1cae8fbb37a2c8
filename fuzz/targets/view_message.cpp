// Door: the text messages pages of the live view send (host/view: the server drops a message over
// MAX_VIEW_MESSAGE_BYTES unread and hands the others to BrowserDevice::handle_message, which parses
// them with parse_pose_message). The input is a session: lines, each a message, its first byte
// naming one of four pages. Promise: never throws; every message counted once, by what became of it
// (accepted, malformed, out of order); the pose the haptic thread reads is always finite with a unit
// quaternion.
#include "view/browser_device.hpp"
#include "view/pose_message.hpp"
#include "support/promise.hpp"

#include <algorithm>
#include <string>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue::host;
  BrowserDevice device{DevicePose{}};
  std::string_view session = tissue::fuzz::as_text(data, size);
  std::uint64_t handed = 0;
  while (!session.empty()) {
    const std::size_t end = std::min(session.find('\n'), session.size());
    const std::string_view line = session.substr(0, end);
    session.remove_prefix(std::min(end + 1, session.size()));
    if (line.empty()) continue;
    const std::uint64_t page = 1 + static_cast<std::uint8_t>(line[0]) % 4;
    const std::string_view text = line.substr(1);
    if (text.size() > MAX_VIEW_MESSAGE_BYTES) continue;  // dropped unread by the server (view_server.cpp)
    device.handle_message(page, std::string(text));
    ++handed;
    if (static_cast<std::uint8_t>(line[0]) >= 0xf0) device.connection_closed(page);
    tissue::fuzz::require_usable_pose(device.read(0.0), 1e-9, "view");  // normalized in double
  }
  const DeviceCounters c = device.counters();
  if (c.received != handed || c.received != c.accepted + c.malformed + c.out_of_order)
    tissue::fuzz::broken("the view's messages are not each counted once");
  return 0;
}
