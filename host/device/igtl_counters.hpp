// igtl_counters.hpp - what the OpenIGTLink server (igtl/igtl_server.hpp) counts. Here, beside the
// devices' counters, so that the session summary (output/) carries it without the server.
#pragma once

#include <cstdint>

namespace tissue::host {

/// received = accepted + malformed + oversized + out_of_order + duplicate + ignored.
struct IgtlCounters {
  std::uint64_t connections = 0, refused_connections = 0;
  std::uint64_t received = 0, accepted = 0, malformed = 0, oversized = 0, out_of_order = 0, duplicate = 0, ignored = 0;
  std::uint64_t forces_sent = 0, forces_dropped = 0, surfaces_sent = 0, surfaces_skipped = 0;
};

}  // namespace tissue::host
