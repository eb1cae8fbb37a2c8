// view_server.cpp - see view_server.hpp. C++17 (websocketpp 0.8.2 is not C++20-clean).
#include "view/view_server.hpp"

#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include <chrono>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

namespace tissue::host {
namespace {

using Server = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;

struct StaticFile {
  std::string content;
  std::string mime;
};

const std::vector<std::pair<std::string, std::string>> STATIC_FILES = {
    {"index.html", "text/html; charset=utf-8"},
    {"view.js", "text/javascript; charset=utf-8"},
    {"three.module.js", "text/javascript; charset=utf-8"},
    {"OrbitControls.js", "text/javascript; charset=utf-8"}};

// The path and the token of a resource "/path?token=...".
void split_resource(const std::string& resource, std::string& path, std::string& token) {
  const auto question = resource.find('?');
  path = resource.substr(0, question);
  token.clear();
  if (question == std::string::npos) return;
  std::istringstream query(resource.substr(question + 1));
  std::string pair;
  while (std::getline(query, pair, '&')) {
    if (pair.rfind("token=", 0) == 0) token = pair.substr(6);
  }
}

}  // namespace

struct ViewServer::Impl {
  struct Client {
    std::uint64_t id = 0;
    bool needs_triangles = true;
    std::uint32_t revision = 0;
    std::chrono::steady_clock::time_point window_start{};
    int window_messages = 0;
  };

  ViewServerSettings settings;
  MessageHandler on_message;
  CloseHandler on_close;
  TickHandler on_tick;
  std::map<std::string, StaticFile> files;

  Server server;
  std::unique_ptr<asio::steady_timer> timer;
  std::thread thread;
  bool running = false;
  std::uint16_t bound_port = 0;

  // Server thread only.
  std::map<Handle, Client, std::owner_less<Handle>> clients;
  std::uint64_t next_id = 1;

  // Shared with the publishing threads.
  mutable std::mutex mutex;
  std::string hello = "{\"type\":\"hello\",\"version\":1}";
  std::shared_ptr<const std::string> frame, frame_with_triangles;
  std::uint32_t revision = 0;
  bool frame_pending = false;
  std::string stats;
  bool stats_pending = false;
  ViewServerCounters counters;

  void count(std::uint64_t ViewServerCounters::*field, std::uint64_t by = 1) {
    std::lock_guard<std::mutex> lock(mutex);
    counters.*field += by;
  }

  bool token_ok(const std::string& token) const { return settings.token.empty() || token == settings.token; }

  void serve_http(Handle handle) {
    Server::connection_ptr connection = server.get_con_from_hdl(handle);
    std::string path, token;
    split_resource(connection->get_resource(), path, token);
    if (!token_ok(token)) {
      connection->set_status(websocketpp::http::status_code::forbidden);
      connection->set_body("a token is required: open the address tissue-host printed\n");
      count(&ViewServerCounters::refused);
      return;
    }
    const std::string name = path == "/" ? "index.html" : path.substr(1);
    const auto file = files.find(name);
    if (file == files.end()) {
      connection->set_status(websocketpp::http::status_code::not_found);
      connection->set_body("not found\n");
      return;
    }
    connection->set_status(websocketpp::http::status_code::ok);
    connection->append_header("Content-Type", file->second.mime);
    connection->append_header("Cache-Control", "no-store");
    connection->set_body(file->second.content);
  }

  bool validate(Handle handle) {
    Server::connection_ptr connection = server.get_con_from_hdl(handle);
    std::string path, token;
    split_resource(connection->get_resource(), path, token);
    if (path == "/ws" && token_ok(token)) return true;
    connection->set_status(path == "/ws" ? websocketpp::http::status_code::forbidden
                                         : websocketpp::http::status_code::not_found);
    count(&ViewServerCounters::refused);
    return false;
  }

  void opened(Handle handle) {
    Client client;
    client.id = next_id++;
    client.window_start = std::chrono::steady_clock::now();
    clients[handle] = client;
    std::string greeting;
    {
      std::lock_guard<std::mutex> lock(mutex);
      ++counters.connections;
      counters.open = clients.size();
      greeting = hello;
    }
    websocketpp::lib::error_code ignored;
    server.send(handle, greeting, websocketpp::frame::opcode::text, ignored);
    send_frame_to(handle, clients[handle]);
  }

  void closed(Handle handle) {
    const auto client = clients.find(handle);
    if (client == clients.end()) return;
    Server::connection_ptr connection = server.get_con_from_hdl(handle);
    if (connection->get_local_close_code() == websocketpp::close::status::message_too_big) {
      count(&ViewServerCounters::oversized);
    }
    const std::uint64_t id = client->second.id;
    clients.erase(client);
    {
      std::lock_guard<std::mutex> lock(mutex);
      counters.open = clients.size();
    }
    on_close(id);
  }

  void received(Handle handle, Server::message_ptr message) {
    const auto client = clients.find(handle);
    if (client == clients.end()) return;
    count(&ViewServerCounters::messages);
    if (message->get_opcode() != websocketpp::frame::opcode::text) {
      count(&ViewServerCounters::binary);
      return;
    }
    if (message->get_payload().size() > settings.max_message_bytes) {
      count(&ViewServerCounters::oversized);
      return;
    }
    Client& c = client->second;
    const auto now = std::chrono::steady_clock::now();
    if (now - c.window_start >= std::chrono::seconds(1)) {
      c.window_start = now;
      c.window_messages = 0;
    }
    if (++c.window_messages > settings.max_messages_per_s) {
      count(&ViewServerCounters::flood);
      return;
    }
    on_message(c.id, message->get_payload());
  }

  // Sends the newest frame to one page, unless it still holds too much unsent.
  void send_frame_to(Handle handle, Client& client) {
    std::shared_ptr<const std::string> plain, full;
    std::uint32_t current = 0;
    {
      std::lock_guard<std::mutex> lock(mutex);
      plain = frame;
      full = frame_with_triangles;
      current = revision;
    }
    if (!plain || !full) return;
    Server::connection_ptr connection = server.get_con_from_hdl(handle);
    if (connection->get_buffered_amount() > settings.max_buffered_bytes) {
      count(&ViewServerCounters::frames_skipped);
      return;
    }
    const bool triangles = client.needs_triangles || client.revision != current;
    const std::string& bytes = triangles ? *full : *plain;
    websocketpp::lib::error_code error;
    server.send(handle, bytes.data(), bytes.size(), websocketpp::frame::opcode::binary, error);
    if (error) return;
    client.needs_triangles = false;
    client.revision = current;
    count(&ViewServerCounters::frames_sent);
  }

  void flush() {
    bool send_frames = false, send_stats = false;
    std::string text;
    {
      std::lock_guard<std::mutex> lock(mutex);
      send_frames = frame_pending;
      frame_pending = false;
      send_stats = stats_pending;
      stats_pending = false;
      if (send_stats) text = stats;
    }
    for (auto& [handle, client] : clients) {
      if (send_frames) send_frame_to(handle, client);
      if (send_stats) {
        websocketpp::lib::error_code ignored;
        server.send(handle, text, websocketpp::frame::opcode::text, ignored);
      }
    }
  }

  void tick() {
    on_tick();
    timer->expires_after(std::chrono::milliseconds(100));
    timer->async_wait([this](const asio::error_code& error) {
      if (!error) tick();
    });
  }
};

ViewServer::ViewServer(ViewServerSettings settings, MessageHandler on_message, CloseHandler on_close,
                       TickHandler on_tick)
    : m_impl(std::make_unique<Impl>()) {
  m_impl->settings = std::move(settings);
  m_impl->on_message = std::move(on_message);
  m_impl->on_close = std::move(on_close);
  m_impl->on_tick = std::move(on_tick);
}

ViewServer::~ViewServer() { stop(); }

void ViewServer::start() {
  Impl& impl = *m_impl;
  if (impl.running) return;
  for (const auto& [name, mime] : STATIC_FILES) {
    std::ifstream in(impl.settings.static_dir + "/" + name, std::ios::binary);
    if (!in) throw ViewServerError("view: " + impl.settings.static_dir + "/" + name + " is missing (build the project)");
    std::ostringstream content;
    content << in.rdbuf();
    impl.files[name] = StaticFile{content.str(), mime};
  }
  Server& server = impl.server;
  server.clear_access_channels(websocketpp::log::alevel::all);
  server.clear_error_channels(websocketpp::log::elevel::all);
  try {
    server.init_asio();
    server.set_reuse_addr(true);
    server.set_max_message_size(MAX_VIEW_FRAME_BYTES);
    server.set_http_handler([&impl](Handle h) { impl.serve_http(h); });
    server.set_validate_handler([&impl](Handle h) { return impl.validate(h); });
    server.set_open_handler([&impl](Handle h) { impl.opened(h); });
    server.set_close_handler([&impl](Handle h) { impl.closed(h); });
    server.set_fail_handler([&impl](Handle h) { impl.closed(h); });
    server.set_message_handler([&impl](Handle h, Server::message_ptr m) { impl.received(h, m); });
    asio::error_code error;
    const asio::ip::address address = asio::ip::make_address(impl.settings.address, error);
    if (error) throw ViewServerError("view: '" + impl.settings.address + "' is not an IP address");
    websocketpp::lib::error_code listen_error;
    server.listen(asio::ip::tcp::endpoint(address, impl.settings.port), listen_error);
    if (listen_error) {
      throw ViewServerError("view: cannot listen on " + impl.settings.address + ":" +
                            std::to_string(impl.settings.port) + ": " + listen_error.message());
    }
    impl.bound_port = server.get_local_endpoint(listen_error).port();
    server.start_accept();
  } catch (const websocketpp::exception& error) {
    throw ViewServerError(std::string("view: ") + error.what());
  }
  impl.timer = std::make_unique<asio::steady_timer>(server.get_io_service());
  impl.tick();
  impl.running = true;
  impl.thread = std::thread([&server] {
    try {
      server.run();
    } catch (...) {  // a network error must not end the session
    }
  });
}

void ViewServer::stop() {
  Impl& impl = *m_impl;
  if (!impl.running) return;
  impl.running = false;
  asio::post(impl.server.get_io_service(), [&impl] {
    websocketpp::lib::error_code ignored;
    impl.server.stop_listening(ignored);
    impl.timer->cancel();
    for (auto& entry : impl.clients) impl.server.close(entry.first, websocketpp::close::status::going_away, "", ignored);
  });
  // Give the pages a moment to take the close, then stop the loop whatever they do.
  for (int k = 0; k < 50 && counters().open > 0; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  impl.server.stop();
  if (impl.thread.joinable()) impl.thread.join();
}

std::uint16_t ViewServer::port() const { return m_impl->bound_port; }

void ViewServer::set_hello(std::string json) {
  std::lock_guard<std::mutex> lock(m_impl->mutex);
  m_impl->hello = std::move(json);
}

void ViewServer::publish_frame(std::shared_ptr<const std::string> frame,
                               std::shared_ptr<const std::string> frame_with_triangles,
                               std::uint32_t topology_revision) {
  Impl& impl = *m_impl;
  {
    std::lock_guard<std::mutex> lock(impl.mutex);
    impl.frame = std::move(frame);
    impl.frame_with_triangles = std::move(frame_with_triangles);
    impl.revision = topology_revision;
    if (impl.frame_pending) return;  // a flush is queued already; it will take this frame
    impl.frame_pending = true;
  }
  if (impl.running) asio::post(impl.server.get_io_service(), [&impl] { impl.flush(); });
}

void ViewServer::publish_stats(std::string json) {
  Impl& impl = *m_impl;
  {
    std::lock_guard<std::mutex> lock(impl.mutex);
    impl.stats = std::move(json);
    if (impl.stats_pending) return;
    impl.stats_pending = true;
  }
  if (impl.running) asio::post(impl.server.get_io_service(), [&impl] { impl.flush(); });
}

ViewServerCounters ViewServer::counters() const {
  std::lock_guard<std::mutex> lock(m_impl->mutex);
  return m_impl->counters;
}

}  // namespace tissue::host
