// IgtlServer (see igtl_server.hpp): a poll loop over the listening socket, the client and an eventfd.
#include "igtl/igtl_server.hpp"

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <stdexcept>
#include <system_error>

namespace tissue::host {
namespace {

[[noreturn]] void refuse(const std::string& what) { throw std::runtime_error("OpenIGTLink server: " + what); }

// Bytes read from the client per wake-up at most, so that a flood does not hold back the force.
constexpr std::size_t READ_CHUNK = 65536;
constexpr int READ_CHUNKS_PER_WAKE = 8;
// A force message is queued while less than this waits to be sent; a surface only when the queue
// is nearly empty (the client reads slower than we send: the newest frame goes next).
constexpr std::size_t FORCE_QUEUE_LIMIT = 256 * 1024;
constexpr std::size_t SURFACE_QUEUE_LIMIT = 16 * 1024;
// An oversized body up to this is skipped (the stream stays in step); a larger claim ends the connection.
constexpr std::uint64_t MAX_SKIPPED_BODY = 64ULL << 20U;
// How long poll waits when nothing happens, so that stop() is seen even if the wake-up is lost.
constexpr int IDLE_POLL_MS = 100;

void check_settings(const IgtlServerSettings& s) {
  if (!(std::isfinite(s.surface_rate_hz) && s.surface_rate_hz >= 0.0)) {
    refuse("surface_rate must be finite and >= 0 Hz (0: no surface), got " + std::to_string(s.surface_rate_hz));
  }
  if (s.max_body_bytes < 64) refuse("max_body_bytes must be at least 64, got " + std::to_string(s.max_body_bytes));
}

}  // namespace

IgtlServer::IgtlServer(const IgtlServerSettings& settings)
    : m_settings(settings),
      m_address(listen_address("OpenIGTLink server", settings.address, settings.port, settings.allow_remote)),
      m_codec(settings.codec) {
  check_settings(m_settings);
  m_listen = open_bound_socket("OpenIGTLink server", m_address, SOCK_STREAM);
  m_address = bound_address(m_listen);
  m_name = "openigtlink " + m_address.text();
  m_wake = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (m_wake < 0) {
    const int error = errno;
    ::close(m_listen);
    refuse("cannot create an eventfd: " + errno_text(error));
  }
  m_in.reserve(2 * READ_CHUNK);
  m_out.reserve(FORCE_QUEUE_LIMIT + 4096);
  m_thread = std::thread([this] { run(); });
}

IgtlServer::~IgtlServer() {
  m_stop.store(true);
  wake();
  m_thread.join();
  close_client();
  ::close(m_listen);
  ::close(m_wake);
}

void IgtlServer::bump(std::atomic<std::uint64_t>& counter) {
  // One writer (the server's thread): a plain load and store, no locked read-modify-write.
  counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

IgtlCounters IgtlServer::counters() const {
  IgtlCounters c;
  c.connections = m_connections.load(std::memory_order_relaxed);
  c.refused_connections = m_refused.load(std::memory_order_relaxed);
  c.received = m_received.load(std::memory_order_relaxed);
  c.accepted = m_accepted.load(std::memory_order_relaxed);
  c.malformed = m_malformed.load(std::memory_order_relaxed);
  c.oversized = m_oversized.load(std::memory_order_relaxed);
  c.out_of_order = m_out_of_order.load(std::memory_order_relaxed);
  c.duplicate = m_duplicate.load(std::memory_order_relaxed);
  c.ignored = m_ignored.load(std::memory_order_relaxed);
  c.forces_sent = m_forces_sent.load(std::memory_order_relaxed);
  c.forces_dropped = m_forces_dropped.load(std::memory_order_relaxed);
  c.surfaces_sent = m_surfaces_sent.load(std::memory_order_relaxed);
  c.surfaces_skipped = m_surfaces_skipped.load(std::memory_order_relaxed);
  return c;
}

void IgtlServer::wake() {
  const std::uint64_t one = 1;
  // Non-blocking; a full counter (never in practice) only means the server is already awake.
  [[maybe_unused]] const ssize_t written = ::write(m_wake, &one, sizeof(one));
}

bool IgtlServer::take_pose(IgtlPoseSample& sample) {
  if (!m_pose.update()) return false;
  sample = m_pose.read_buffer();
  return true;
}

void IgtlServer::send_force(const std::array<double, 3>& force_n) {
  m_force.write_buffer() = force_n;
  m_force.publish();
  wake();
}

bool IgtlServer::surface_due(double time_s) const {
  return m_settings.surface_rate_hz > 0.0 && time_s + 1e-9 >= m_next_surface_s;
}

void IgtlServer::publish_surface(double time_s) {
  m_surface.publish();
  while (m_next_surface_s <= time_s + 1e-9) m_next_surface_s += 1.0 / m_settings.surface_rate_hz;
  wake();
}

void IgtlServer::run() {
  while (!m_stop.load()) {
    std::array<pollfd, 3> fds{};
    fds[0] = {m_listen, POLLIN, 0};
    fds[1] = {m_wake, POLLIN, 0};
    nfds_t count = 2;
    if (m_client >= 0) {
      const bool pending = m_out_sent < m_out.size();
      fds[2] = {m_client, static_cast<short>(POLLIN | (pending ? POLLOUT : 0)), 0};
      count = 3;
    }
    if (::poll(fds.data(), count, IDLE_POLL_MS) < 0 && errno != EINTR) break;
    if ((fds[1].revents & POLLIN) != 0) {
      std::uint64_t ignored = 0;
      [[maybe_unused]] const ssize_t read = ::read(m_wake, &ignored, sizeof(ignored));
    }
    if ((fds[0].revents & POLLIN) != 0) accept_client();
    if (m_client >= 0 && count == 3 && (fds[2].revents & (POLLIN | POLLHUP | POLLERR)) != 0) read_client();
    queue_outgoing();
    flush();
  }
}

void IgtlServer::accept_client() {
  const int client = ::accept4(m_listen, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
  if (client < 0) return;
  if (m_client >= 0) read_client();  // a client that left (its EOF waiting) makes room for this one
  if (m_client >= 0) {               // one client at a time: a second one would fight the first for the tool
    ::close(client);
    bump(m_refused);
    return;
  }
  const int yes = 1;
  ::setsockopt(client, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof(yes));  // a force message per tick, now
  m_client = client;
  m_in.clear();
  m_out.clear();
  m_out_sent = 0;
  m_discard = 0;
  m_last_timestamp = {};  // a new client has its own clock
  bump(m_connections);
}

void IgtlServer::close_client() {
  if (m_client < 0) return;
  ::close(m_client);
  m_client = -1;
  m_in.clear();
  m_out.clear();
  m_out_sent = 0;
  m_discard = 0;
}

void IgtlServer::read_client() {
  for (int chunk = 0; chunk < READ_CHUNKS_PER_WAKE && m_client >= 0; ++chunk) {
    const std::size_t old_size = m_in.size();
    m_in.resize(old_size + READ_CHUNK);
    const ssize_t got = ::recv(m_client, m_in.data() + old_size, READ_CHUNK, MSG_DONTWAIT);
    if (got <= 0) {
      m_in.resize(old_size);
      if (got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR)) return;
      close_client();  // the client closed (0) or the connection failed
      return;
    }
    m_in.resize(old_size + static_cast<std::size_t>(got));
    // Whole messages out of the stream; a partial one waits for the rest.
    std::size_t offset = 0;
    while (true) {
      const std::size_t available = m_in.size() - offset;
      if (m_discard > 0) {
        const std::size_t skipped = static_cast<std::size_t>(std::min<std::uint64_t>(m_discard, available));
        offset += skipped;
        m_discard -= skipped;
        if (m_discard > 0) break;
        continue;
      }
      if (available < igtl_link::HEADER_SIZE) break;
      const igtl_link::Header header = igtl_link::read_header(
          std::span<const std::uint8_t, igtl_link::HEADER_SIZE>(m_in.data() + offset, igtl_link::HEADER_SIZE));
      if (header.body_size > m_settings.max_body_bytes) {
        bump(m_received);
        bump(m_oversized);
        if (header.body_size > MAX_SKIPPED_BODY) {  // no client means it: the stream cannot be trusted
          close_client();
          return;
        }
        offset += igtl_link::HEADER_SIZE;
        m_discard = header.body_size;
        continue;
      }
      const std::size_t size = igtl_link::HEADER_SIZE + static_cast<std::size_t>(header.body_size);
      if (available < size) break;
      handle_message(header, offset, size);
      offset += size;
    }
    m_in.erase(m_in.begin(), m_in.begin() + static_cast<std::ptrdiff_t>(offset));
  }
}

void IgtlServer::handle_message(const igtl_link::Header& header, std::size_t offset, std::size_t size) {
  bump(m_received);
  IgtlPoseSample& sample = m_pose.write_buffer();
  const std::span<const std::uint8_t> message(m_in.data() + offset, size);
  switch (m_codec.decode_pose(header, message, sample.pose)) {
    case igtl_link::Verdict::ignored:
      bump(m_ignored);
      return;
    case igtl_link::Verdict::malformed:
      bump(m_malformed);
      return;
    case igtl_link::Verdict::pose:
      break;
  }
  // The header's timestamp orders one tool's poses (0: the sender does not stamp them).
  std::uint64_t& last = m_last_timestamp[static_cast<std::size_t>(sample.pose.mode)];
  if (header.timestamp != 0 && header.timestamp <= last) {
    bump(header.timestamp == last ? m_duplicate : m_out_of_order);
    return;
  }
  last = std::max(last, header.timestamp);
  bump(m_accepted);
  sample.accepted = m_accepted.load(std::memory_order_relaxed);  // this thread is its only writer
  m_pose.publish();
}

void IgtlServer::queue_outgoing() {
  if (m_force.update() && m_client >= 0) {
    if (m_out.size() - m_out_sent < FORCE_QUEUE_LIMIT) {
      m_codec.append_force(m_force.read_buffer(), m_out);
      bump(m_forces_sent);
    } else {
      bump(m_forces_dropped);
    }
  }
  if (m_surface.update() && m_client >= 0) {
    if (m_out.size() - m_out_sent < SURFACE_QUEUE_LIMIT) {
      m_codec.append_surface(m_surface.read_buffer(), m_out);
      bump(m_surfaces_sent);
    } else {
      bump(m_surfaces_skipped);
    }
  }
}

void IgtlServer::flush() {
  while (m_client >= 0 && m_out_sent < m_out.size()) {
    const ssize_t sent =
        ::send(m_client, m_out.data() + m_out_sent, m_out.size() - m_out_sent, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (sent < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) break;
      close_client();
      return;
    }
    m_out_sent += static_cast<std::size_t>(sent);
  }
  if (m_out_sent == m_out.size()) {
    m_out.clear();
    m_out_sent = 0;
  } else if (m_out_sent > FORCE_QUEUE_LIMIT) {
    m_out.erase(m_out.begin(), m_out.begin() + static_cast<std::ptrdiff_t>(m_out_sent));
    m_out_sent = 0;
  }
}

}  // namespace tissue::host
