// The live view's pieces without a browser (label "host"): the page's pose message accepted only
// in its exact shape; the binary frame laid out as VIEW_PROTOCOL.md says; the browser device
// turning messages into the hand's pose, dropping out-of-order ones, withdrawing the tool when
// its page disconnects or goes silent. The browser end to end: tests/host/browser/.
#include "view/browser_device.hpp"
#include "view/pose_message.hpp"
#include "view/view_frame.hpp"
#include "view/view_server.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <fstream>
#include <string>
#include <thread>

namespace tissue::host {
namespace {

const std::string GOOD =
    R"({"type":"pose","seq":7,"position_m":[0.01,-0.02,0.03],"orientation_wxyz":[2,0,0,0],"mode":"scalpel"})";

TEST(ViewPoseMessage, AcceptsTheDocumentedShape) {
  const auto message = parse_pose_message(GOOD);
  ASSERT_TRUE(message.has_value());
  EXPECT_EQ(message->seq, 7u);
  EXPECT_DOUBLE_EQ(message->pose.position_m[1], -0.02);
  EXPECT_DOUBLE_EQ(message->pose.orientation_wxyz[0], 1.0);  // normalized
  EXPECT_EQ(message->pose.mode, ToolMode::scalpel);
}

TEST(ViewPoseMessage, RefusesEverythingElseWithAReason) {
  const std::vector<std::string> bad = {
      "",
      "{",
      GOOD.substr(0, GOOD.size() / 2),  // truncated
      "[1,2,3]",
      R"({"type":"nonsense"})",
      R"({"type":"pose","seq":-1,"position_m":[0,0,0],"orientation_wxyz":[1,0,0,0],"mode":"probe"})",
      R"({"type":"pose","seq":1.5,"position_m":[0,0,0],"orientation_wxyz":[1,0,0,0],"mode":"probe"})",
      R"({"type":"pose","seq":1,"position_m":[0,0],"orientation_wxyz":[1,0,0,0],"mode":"probe"})",
      R"({"type":"pose","seq":1,"position_m":["0","0","0"],"orientation_wxyz":[1,0,0,0],"mode":"probe"})",
      R"({"type":"pose","seq":1,"position_m":[0,0,1e999],"orientation_wxyz":[1,0,0,0],"mode":"probe"})",
      R"({"type":"pose","seq":1,"position_m":[0,0,0],"orientation_wxyz":[0,0,0,0],"mode":"probe"})",
      R"({"type":"pose","seq":1,"position_m":[0,0,0],"orientation_wxyz":[1,0,0,0],"mode":"laser"})",
      R"({"type":"pose","seq":1,"position_m":[0,0,0],"orientation_wxyz":[1,0,0,0]})",
      std::string(600, ' ') + GOOD,  // oversized, even if valid inside
  };
  for (const std::string& text : bad) {
    std::string why;
    EXPECT_FALSE(parse_pose_message(text, &why).has_value()) << text;
    EXPECT_FALSE(why.empty()) << text;
  }
}

// A little-endian value of a frame at a byte offset.
template <class T>
T read_at(const std::string& bytes, std::size_t offset) {
  T value;
  std::memcpy(&value, bytes.data() + offset, sizeof(T));
  return value;
}

TEST(ViewFrame, HeaderPositionsAndTrianglesAsDocumented) {
  SurfaceFrame frame;
  frame.time_s = 1.25;
  frame.positions_m = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  frame.triangles = {0, 2, 1, 0, 1, 3};
  frame.mesh_triangle_count = 1;
  frame.has_tool = true;
  frame.tool_mode = 2;
  frame.tool_tip_m = {0.1, 0.2, 0.3};
  frame.tool_handle_m = {0.1, 0.2, 0.4};
  frame.contact_active = true;
  frame.contact_point_m = {0.5, 0.5, 0.5};
  ViewOverlay overlay{{1.0, -2.0, 3.0}, 3.3, 4};
  std::string plain, full;
  encode_view_frames(frame, overlay, plain, full);
  EXPECT_EQ(plain.size(), VIEW_FRAME_HEADER_BYTES + 4 * 12);
  EXPECT_EQ(full.size(), VIEW_FRAME_HEADER_BYTES + 4 * 12 + 4 * 6);
  const auto u32 = [&full](std::size_t offset) { return read_at<std::uint32_t>(full, offset); };
  const auto f32 = [&full](std::size_t offset) { return read_at<float>(full, offset); };
  double time;
  std::memcpy(&time, full.data() + 24, 8);
  EXPECT_EQ(u32(0), VIEW_FRAME_MAGIC);
  EXPECT_EQ(u32(4), 1u);
  EXPECT_EQ(u32(8), 4u);
  EXPECT_EQ(u32(12), 2u);
  EXPECT_EQ(u32(16), 1u);
  EXPECT_EQ(u32(20), 4u);
  EXPECT_EQ(time, 1.25);
  EXPECT_FLOAT_EQ(f32(32 + 8), 0.3f);   // tip z
  EXPECT_FLOAT_EQ(f32(44 + 8), 0.4f);   // handle z
  EXPECT_EQ(u32(56), 2u);               // scalpel
  EXPECT_EQ(u32(60), 1u);               // contact
  EXPECT_FLOAT_EQ(f32(76 + 4), -2.0f);  // device force y
  EXPECT_FLOAT_EQ(f32(88), 3.3f);
  EXPECT_FLOAT_EQ(f32(96 + 4 * 3), 1.0f);                  // vertex 1 x
  EXPECT_EQ(u32(96 + 4 * 12 + 4 * 5), 3u);                 // the last index
  EXPECT_EQ(std::memcmp(&plain[4], "\0\0\0\0", 4), 0);     // no triangles flag
  frame.positions_m[4] = std::nan("");
  EXPECT_THROW(encode_view_frames(frame, overlay, plain, full), OutputError);
}

// A frame with an embedding goes out mapped: the nodes as positions (the plain frame is 12 bytes per
// node, not per point), the embedding with the triangles; mapping the points from the bytes as the
// page does gives the frame's positions (to float precision). An embedding the nodes do not fit is
// refused.
TEST(ViewFrame, AMappedFrameCarriesTheNodesAndOnceTheEmbedding) {
  auto embedding = std::make_shared<ports::SurfaceEmbedding>();
  embedding->node_count = 4;  // a tet's corners; five points in it, a fan of four triangles
  embedding->point_nodes = {0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3};
  embedding->point_weights = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.25, 0.25, 0.25, 0.25};
  embedding->triangles = {4, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0};
  embedding->cut_triangle_count = 1;
  SurfaceFrame frame;
  frame.embedding = embedding;
  frame.node_positions_m = {0, 0, 0, 0.2, 0, 0, 0, 0.2, 0, 0, 0, 0.2};
  ports::SurfaceNodes nodes{0, frame.node_positions_m};
  ports::map_points(*embedding, nodes, frame.positions_m);
  frame.triangles = embedding->triangles;
  frame.mesh_triangle_count = 3;
  std::string plain, full;
  encode_view_frames(frame, ViewOverlay{}, plain, full);
  const auto u32 = [&full](std::size_t offset) { return read_at<std::uint32_t>(full, offset); };
  const auto f32 = [&full](std::size_t offset) { return read_at<float>(full, offset); };
  const std::size_t nodes_n = 4, points = 5, triangles = 4;
  EXPECT_EQ(plain.size(), VIEW_FRAME_HEADER_BYTES + 12 * nodes_n);
  EXPECT_EQ(full.size(), VIEW_FRAME_HEADER_BYTES + 12 * nodes_n + 32 * points + 12 * triangles);
  EXPECT_EQ(u32(4), VIEW_FRAME_TRIANGLES | VIEW_FRAME_MAPPED);
  EXPECT_EQ(u32(8), nodes_n);
  EXPECT_EQ(u32(12), triangles);
  EXPECT_EQ(u32(16), 3u);
  EXPECT_EQ(u32(92), points);
  const std::size_t at_nodes = VIEW_FRAME_HEADER_BYTES, at_index = at_nodes + 12 * nodes_n,
                    at_weights = at_index + 16 * points, at_triangles = at_weights + 16 * points;
  for (std::size_t i = 0; i < points; ++i) {
    for (std::size_t c = 0; c < 3; ++c) {
      double x = 0.0;
      for (std::size_t k = 0; k < 4; ++k) {
        x += f32(at_weights + 4 * (4 * i + k)) * f32(at_nodes + 4 * (3 * u32(at_index + 4 * (4 * i + k)) + c));
      }
      EXPECT_NEAR(x, frame.positions_m[3 * i + c], 1e-7) << "point " << i;
    }
  }
  EXPECT_EQ(u32(at_triangles), 4u);
  EXPECT_EQ(u32(at_triangles + 4 * 11), 0u);
  frame.node_positions_m.resize(9);
  EXPECT_THROW(encode_view_frames(frame, ViewOverlay{}, plain, full), OutputError);
}

DevicePose away() {
  DevicePose pose;
  pose.position_m = {0.0, 0.0, 0.1};
  return pose;
}

std::string pose_text(std::uint64_t seq, double x, const char* mode) {
  return R"({"type":"pose","seq":)" + std::to_string(seq) + R"(,"position_m":[)" + std::to_string(x) +
         R"(,0,0],"orientation_wxyz":[1,0,0,0],"mode":")" + mode + "\"}";
}

TEST(BrowserDevice, MessagesBecomeTheHandsPose) {
  BrowserDevice device(away());
  EXPECT_EQ(device.read(0.0).mode, ToolMode::none);
  device.handle_message(1, pose_text(1, 0.01, "probe"));
  DevicePose pose = device.read(0.001);
  EXPECT_EQ(pose.mode, ToolMode::probe);
  EXPECT_DOUBLE_EQ(pose.position_m[0], 0.01);
  device.handle_message(1, pose_text(1, 0.02, "probe"));  // replayed seq
  device.handle_message(1, pose_text(0, 0.03, "probe"));  // older
  device.handle_message(1, "{\"type\":\"pose\"");         // truncated
  EXPECT_DOUBLE_EQ(device.read(0.002).position_m[0], 0.01);
  device.handle_message(2, pose_text(0, 0.04, "scalpel"));  // another page: its own sequence
  EXPECT_EQ(device.read(0.003).mode, ToolMode::scalpel);
  const DeviceCounters c = device.counters();
  EXPECT_EQ(c.received, 5u);
  EXPECT_EQ(c.accepted, 2u);
  EXPECT_EQ(c.out_of_order, 2u);
  EXPECT_EQ(c.malformed, 1u);
}

TEST(BrowserDevice, ADisconnectedOrSilentPageWithdrawsTheTool) {
  BrowserDevice device(away());
  device.handle_message(3, pose_text(1, 0.01, "scalpel"));
  device.connection_closed(4);  // not the page holding the hand
  EXPECT_EQ(device.read(0.0).mode, ToolMode::scalpel);
  device.connection_closed(3);
  DevicePose pose = device.read(0.001);
  EXPECT_EQ(pose.mode, ToolMode::none);
  EXPECT_DOUBLE_EQ(pose.position_m[0], 0.01);  // the pose is kept

  device.handle_message(5, pose_text(1, 0.02, "probe"));
  device.tick();
  EXPECT_EQ(device.read(0.002).mode, ToolMode::probe);  // not silent yet
  std::this_thread::sleep_for(BrowserDevice::SILENCE_LIMIT + std::chrono::milliseconds(100));
  device.tick();
  EXPECT_EQ(device.read(0.003).mode, ToolMode::none);
  EXPECT_EQ(device.counters().watchdog_trips, 2u);
}

// A TCP connection to the loopback port, with a receive buffer of `receive_buffer_bytes` when > 0;
// -1 if it cannot connect.
int connect_loopback(std::uint16_t port, int receive_buffer_bytes = 0) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (receive_buffer_bytes > 0) setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer_bytes, sizeof(receive_buffer_bytes));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// One HTTP GET over loopback; the status line of the answer ("" if none).
std::string http_status(std::uint16_t port, const std::string& resource) {
  const int fd = connect_loopback(port);
  if (fd < 0) return "";
  const std::string request = "GET " + resource + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
  (void)send(fd, request.data(), request.size(), 0);
  std::string answer;
  char buffer[4096];
  for (ssize_t n; (n = recv(fd, buffer, sizeof(buffer), 0)) > 0;) answer.append(buffer, static_cast<std::size_t>(n));
  close(fd);
  return answer.substr(0, answer.find("\r\n"));
}

// Server settings on any free loopback port, with the four static files as small stand-ins.
ViewServerSettings test_server_settings() {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "tissue_test_view_static";
  std::filesystem::create_directories(dir);
  for (const char* name : {"index.html", "view.js", "three.module.js", "OrbitControls.js"}) {
    std::ofstream(dir / name) << "// " << name << "\n";
  }
  ViewServerSettings settings;
  settings.port = 0;
  settings.static_dir = dir.string();
  return settings;
}

TEST(ViewServer, ATokenIsRequiredWhenSetAndOnlyTheFourFilesAreServed) {
  ViewServerSettings settings = test_server_settings();
  settings.token = "s3cret";
  ViewServer server(settings, [](std::uint64_t, const std::string&) {}, [](std::uint64_t) {}, [] {});
  server.start();
  ASSERT_GT(server.port(), 0);
  EXPECT_EQ(http_status(server.port(), "/"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(http_status(server.port(), "/?token=wrong"), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(http_status(server.port(), "/?token=s3cret"), "HTTP/1.1 200 OK");
  EXPECT_EQ(http_status(server.port(), "/view.js?token=s3cret"), "HTTP/1.1 200 OK");
  EXPECT_EQ(http_status(server.port(), "/../etc/passwd?token=s3cret"), "HTTP/1.1 404 Not Found");
  EXPECT_EQ(server.counters().refused, 2u);
  ViewServerSettings same_port = settings;
  same_port.port = server.port();
  ViewServer second(same_port, [](std::uint64_t, const std::string&) {}, [](std::uint64_t) {}, [] {});
  EXPECT_THROW(second.start(), ViewServerError);  // the port is taken: a clear error, not a crash
  server.stop();

  ViewServerSettings missing = settings;
  missing.static_dir += "/nowhere";
  ViewServer without_files(missing, [](std::uint64_t, const std::string&) {}, [](std::uint64_t) {}, [] {});
  EXPECT_THROW(without_files.start(), ViewServerError);
}

TEST(ViewServer, APageThatDoesNotReadIsSkippedNotWaitedFor) {
  // A client completes the WebSocket handshake and then never reads. Publishing goes on at once
  // (publish_frame only swaps pointers); the server skips the page once more than
  // max_buffered_bytes wait unsent, and counts it.
  ViewServer server(test_server_settings(), [](std::uint64_t, const std::string&) {}, [](std::uint64_t) {}, [] {});
  server.start();
  // A small receive buffer: the backlog builds in the server, not in the kernel.
  const int fd = connect_loopback(server.port(), 4096);
  ASSERT_GE(fd, 0);
  const std::string upgrade =
      "GET /ws HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n";
  ASSERT_EQ(send(fd, upgrade.data(), upgrade.size(), 0), static_cast<ssize_t>(upgrade.size()));
  char reply[256];
  ASSERT_GT(recv(fd, reply, sizeof(reply) - 1, 0), 0);  // "HTTP/1.1 101 Switching Protocols"...
  reply[12] = '\0';
  EXPECT_STREQ(reply, "HTTP/1.1 101");
  for (int k = 0; k < 200 && server.counters().open == 0; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(server.counters().open, 1u);

  const auto frame = std::make_shared<const std::string>(1024 * 1024, 'x');  // beyond any kernel buffer within a few
  for (int k = 0; k < 100; ++k) {
    server.publish_frame(frame, frame, 1);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // let the server's thread flush
  }
  for (int k = 0; k < 100 && server.counters().frames_sent + server.counters().frames_skipped < 100; ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const ViewServerCounters c = server.counters();
  EXPECT_GT(c.frames_skipped, 0u);
  EXPECT_LT(c.frames_sent, 100u);
  close(fd);
  server.stop();
}

}  // namespace
}  // namespace tissue::host
