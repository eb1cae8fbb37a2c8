// socket_address.hpp - a numeric IPv4/IPv6 address and port for the network devices (UDP,
// OpenIGTLink) to bind, and the rule they share: loopback only unless remote access is asked for.
#pragma once

#include <sys/socket.h>

#include <cstdint>
#include <string>

namespace tissue::host {

struct SocketAddress {
  sockaddr_storage storage{};
  socklen_t length = 0;
  /// "127.0.0.1:47001" or "[::1]:47001".
  [[nodiscard]] std::string text() const;
  [[nodiscard]] std::uint16_t port() const;
  /// 127.0.0.0/8, ::1 or ::ffff:127.x.y.z.
  [[nodiscard]] bool is_loopback() const;
};

/// @p host (numeric IPv4 or IPv6) and @p port. Throws std::runtime_error prefixed by @p who when
/// the address is not numeric, or is not loopback (the wildcards 0.0.0.0 and :: included) and
/// @p allow_remote is false: anyone who can reach such an address moves the tool.
SocketAddress listen_address(const std::string& who, const std::string& host, std::uint16_t port, bool allow_remote);

/// A non-blocking, close-on-exec socket of @p type (SOCK_DGRAM or SOCK_STREAM) bound to @p address;
/// a stream socket also listens (and may rebind a port in TIME_WAIT). Throws std::runtime_error
/// "<who>: cannot bind udp <address>: <reason>" (or "cannot listen on tcp ...").
int open_bound_socket(const std::string& who, const SocketAddress& address, int type);

/// The reason for an errno value, as text.
std::string errno_text(int error);

/// The address @p socket is bound to (e.g. to learn an ephemeral port).
SocketAddress bound_address(int socket);

}  // namespace tissue::host
