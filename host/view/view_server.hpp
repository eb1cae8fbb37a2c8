// view_server.hpp - the live view's HTTP + WebSocket server (VIEW_PROTOCOL.md) on websocketpp and
// standalone asio (Debian's libwebsocketpp-dev, libasio-dev), behind this interface: it serves the
// page's static files, sends each connected page the hello, the newest frame (skipping a page that
// has not taken the previous one) and the stats, and hands the pages' text messages to a callback
// after dropping the oversized ones and a flood. One thread of its own runs everything network;
// publishing is a copy under a short lock, never a wait on a client. Nothing here knows the tissue.
//
// This header and view_server.cpp are C++17 (websocketpp 0.8.2 does not compile as C++20).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace tissue::host {

class ViewServerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The largest WebSocket message the server receives whole [bytes]: beyond it the connection is
/// closed before the message is buffered (counted as oversized); up to it, one over max_message_bytes
/// is dropped unread.
inline constexpr std::size_t MAX_VIEW_FRAME_BYTES = 64 * 1024;

struct ViewServerSettings {
  std::string address = "127.0.0.1";
  std::uint16_t port = 8080;   ///< 0: any free port (port() tells which)
  std::string token;           ///< required as ?token= when not empty
  std::string static_dir;      ///< index.html, view.js, three.module.js, OrbitControls.js
  std::size_t max_message_bytes = 512;
  int max_messages_per_s = 1000;
  /// A page with more than this many bytes not yet sent gets no new frame (it is skipped).
  std::size_t max_buffered_bytes = 256 * 1024;
};

/// Messages the server itself dropped, and what it sent.
struct ViewServerCounters {
  std::uint64_t connections = 0, open = 0, refused = 0;
  std::uint64_t messages = 0, oversized = 0, flood = 0, binary = 0;
  std::uint64_t frames_sent = 0, frames_skipped = 0;
};

class ViewServer {
 public:
  /// A text message from connection `connection` (messages within the size and rate limits only).
  using MessageHandler = std::function<void(std::uint64_t connection, const std::string& text)>;
  /// A connection closed (or failed).
  using CloseHandler = std::function<void(std::uint64_t connection)>;
  /// Called about every 100 ms on the server's thread (watchdogs).
  using TickHandler = std::function<void()>;

  ViewServer(ViewServerSettings settings, MessageHandler on_message, CloseHandler on_close, TickHandler on_tick);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  /// Binds and starts the server's thread. Throws ViewServerError (address in use, bad address,
  /// missing static files).
  void start();
  /// Closes every connection and joins the thread. Idempotent.
  void stop();
  [[nodiscard]] std::uint16_t port() const;

  /// The hello every page gets first (JSON text).
  void set_hello(std::string json);
  /// The newest frame, without and with triangles, and its topology revision: each page gets the
  /// one it needs (the triangles on its first frame and after a revision change).
  void publish_frame(std::shared_ptr<const std::string> frame, std::shared_ptr<const std::string> frame_with_triangles,
                     std::uint32_t topology_revision);
  /// Sent to every page as text.
  void publish_stats(std::string json);
  [[nodiscard]] ViewServerCounters counters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace tissue::host
