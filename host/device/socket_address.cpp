// SocketAddress (see socket_address.hpp).
#include "device/socket_address.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>

#include <unistd.h>

#include <array>
#include <cerrno>
#include <stdexcept>
#include <system_error>

namespace tissue::host {

std::uint16_t SocketAddress::port() const {
  if (storage.ss_family == AF_INET6) return ntohs(reinterpret_cast<const sockaddr_in6&>(storage).sin6_port);
  return ntohs(reinterpret_cast<const sockaddr_in&>(storage).sin_port);
}

std::string SocketAddress::text() const {
  std::array<char, INET6_ADDRSTRLEN> buffer{};
  const bool v6 = storage.ss_family == AF_INET6;
  if (v6) {
    inet_ntop(AF_INET6, &reinterpret_cast<const sockaddr_in6&>(storage).sin6_addr, buffer.data(), buffer.size());
  } else {
    inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in&>(storage).sin_addr, buffer.data(), buffer.size());
  }
  std::string text;
  text.append(v6 ? "[" : "").append(buffer.data()).append(v6 ? "]:" : ":").append(std::to_string(port()));
  return text;
}

bool SocketAddress::is_loopback() const {
  if (storage.ss_family == AF_INET) {
    return (ntohl(reinterpret_cast<const sockaddr_in&>(storage).sin_addr.s_addr) >> 24U) == 127U;
  }
  const in6_addr& v6 = reinterpret_cast<const sockaddr_in6&>(storage).sin6_addr;
  if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
  // ::ffff:127.x.y.z, an IPv4 loopback address written as IPv6.
  return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
}

SocketAddress listen_address(const std::string& who, const std::string& host, std::uint16_t port, bool allow_remote) {
  SocketAddress address;
  auto& v4 = reinterpret_cast<sockaddr_in&>(address.storage);
  auto& v6 = reinterpret_cast<sockaddr_in6&>(address.storage);
  if (inet_pton(AF_INET, host.c_str(), &v4.sin_addr) == 1) {
    v4.sin_family = AF_INET;
    v4.sin_port = htons(port);
    address.length = sizeof(sockaddr_in);
  } else if (inet_pton(AF_INET6, host.c_str(), &v6.sin6_addr) == 1) {
    v6.sin6_family = AF_INET6;
    v6.sin6_port = htons(port);
    address.length = sizeof(sockaddr_in6);
  } else {
    throw std::runtime_error(who + ": bind address '" + host +
                             "' is not a numeric IPv4 or IPv6 address (e.g. 127.0.0.1 or ::1)");
  }
  if (!address.is_loopback() && !allow_remote) {
    throw std::runtime_error(who + ": refusing to listen on " + address.text() +
                             ": not a loopback address, so any host that reaches it could move the tool. Bind to "
                             "127.0.0.1 or ::1, or set allow_remote to listen on it anyway");
  }
  return address;
}

std::string errno_text(int error) { return std::system_category().message(error); }

int open_bound_socket(const std::string& who, const SocketAddress& address, int type) {
  const bool stream = type == SOCK_STREAM;
  const std::string what = (stream ? "listen on tcp " : "bind udp ") + address.text();
  const int fd = ::socket(address.storage.ss_family, type | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) throw std::runtime_error(who + ": cannot create a socket to " + what + ": " + errno_text(errno));
  const int yes = 1;
  if (stream) ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&address.storage), address.length) != 0 ||
      (stream && ::listen(fd, 4) != 0)) {
    const int error = errno;
    ::close(fd);
    throw std::runtime_error(who + ": cannot " + what + ": " + errno_text(error));
  }
  return fd;
}

SocketAddress bound_address(int socket) {
  SocketAddress address;
  address.length = sizeof(address.storage);
  if (::getsockname(socket, reinterpret_cast<sockaddr*>(&address.storage), &address.length) != 0) address.length = 0;
  return address;
}

}  // namespace tissue::host
