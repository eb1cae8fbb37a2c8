// OpenIGTLink (host/igtl/): the messages against the OpenIGTLink library's own packing and
// unpacking, and the server and device over loopback with a client built from the same library
// (tests/host/igtl_client.*): poses in, forces and surfaces out, every bad message dropped, counted
// and without effect, one client at a time, loopback only, and the silence watchdog, shown to be
// what zeroes the force by switching it off.
#include "igtl/igtl_codec.hpp"
#include "igtl/igtl_device.hpp"
#include "igtl/igtl_server.hpp"
#include "igtl_client.hpp"

#include <igtlMessageHeader.h>
#include <igtlPolyDataMessage.h>
#include <igtlSensorMessage.h>
#include <igtlTransformMessage.h>
#include <igtlUnit.h>
#include <igtl_unit.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

namespace tissue::host {
namespace {

using igtl_link::Codec;
using igtl_link::CodecSettings;
using igtl_link::Verdict;

// A pose 30 degrees about x, at millimetre values a tracker would send.
DevicePose example_pose() {
  DevicePose pose;
  pose.position_m = {0.0125, -0.003, 0.040};
  const double half = 0.5 * (30.0 * M_PI / 180.0);
  pose.orientation_wxyz = {std::cos(half), std::sin(half), 0.0, 0.0};
  pose.mode = ToolMode::probe;
  return pose;
}

// float32 millimetres on the wire: a length of 40 mm keeps ~4e-6 mm, so 1e-8 m is ample and tight.
constexpr double POSITION_TOLERANCE_M = 1e-8;
// A rotation matrix in float32 gives its quaternion to ~1e-7.
constexpr double QUATERNION_TOLERANCE = 1e-6;

void expect_pose(const DevicePose& got, const DevicePose& want) {
  for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(got.position_m[a], want.position_m[a], POSITION_TOLERANCE_M) << a;
  const double sign = got.orientation_wxyz[0] * want.orientation_wxyz[0] >= 0.0 ? 1.0 : -1.0;
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(sign * got.orientation_wxyz[i], want.orientation_wxyz[i], QUATERNION_TOLERANCE) << i;
  }
  EXPECT_EQ(got.mode, want.mode);
}

TEST(IgtlCodec, ATransformInMillimetresIsThePoseInMetresAndItsNameTheInstrument) {
  Codec codec(CodecSettings{});
  DevicePose pose;
  ASSERT_EQ(codec.decode_pose(test::pack_transform("ProbeToTissue", example_pose()), pose), Verdict::pose);
  expect_pose(pose, example_pose());
  DevicePose scalpel = example_pose();
  scalpel.mode = ToolMode::scalpel;
  ASSERT_EQ(codec.decode_pose(test::pack_transform("ScalpelToTissue", scalpel), pose), Verdict::pose);
  expect_pose(pose, scalpel);
  // Another unit on the wire: metres.
  CodecSettings metres;
  metres.length_unit_m = 1.0;
  Codec codec_m(metres);
  ASSERT_EQ(codec_m.decode_pose(test::pack_transform("ProbeToTissue", example_pose(), 1.0), pose), Verdict::pose);
  for (std::size_t a = 0; a < 3; ++a) EXPECT_NEAR(pose.position_m[a], example_pose().position_m[a], 1e-8);
}

TEST(IgtlCodec, PositionMessagesOfAllThreeSizes) {
  Codec codec(CodecSettings{});
  DevicePose pose;
  ASSERT_EQ(codec.decode_pose(test::pack_position("ProbeToTissue", example_pose(), 1e-3, 0, 28), pose), Verdict::pose);
  expect_pose(pose, example_pose());
  ASSERT_EQ(codec.decode_pose(test::pack_position("ProbeToTissue", example_pose(), 1e-3, 0, 24), pose), Verdict::pose);
  expect_pose(pose, example_pose());
  ASSERT_EQ(codec.decode_pose(test::pack_position("ProbeToTissue", example_pose(), 1e-3, 0, 12), pose), Verdict::pose);
  DevicePose upright = example_pose();
  upright.orientation_wxyz = {1.0, 0.0, 0.0, 0.0};  // a position alone: the identity orientation
  expect_pose(pose, upright);
}

TEST(IgtlCodec, CorruptedTruncatedNonRigidAndNonFiniteMessagesAreMalformedOthersIgnored) {
  Codec codec(CodecSettings{});
  DevicePose pose = example_pose();
  const DevicePose untouched = pose;
  const std::vector<std::uint8_t> good = test::pack_transform("ProbeToTissue", example_pose());

  std::vector<std::uint8_t> corrupted = good;
  corrupted[igtl_link::HEADER_SIZE + 5] ^= 0x40U;  // a body byte: the CRC no longer matches
  EXPECT_EQ(codec.decode_pose(corrupted, pose), Verdict::malformed);
  std::vector<std::uint8_t> truncated(good.begin(), good.end() - 4);
  EXPECT_EQ(codec.decode_pose(truncated, pose), Verdict::malformed);
  std::vector<std::uint8_t> version2 = good;
  version2[1] = 2;  // header version 2 (an extended header we do not read)
  EXPECT_EQ(codec.decode_pose(version2, pose), Verdict::malformed);

  igtl::TransformMessage::Pointer scaled = igtl::TransformMessage::New();
  scaled->SetDeviceName("ProbeToTissue");
  igtl::Matrix4x4 matrix;
  igtl::IdentityMatrix(matrix);
  matrix[0][0] = 2.0F;  // a scaling, not a rotation
  scaled->SetMatrix(matrix);
  scaled->Pack();
  const auto* bytes = static_cast<const std::uint8_t*>(scaled->GetPackPointer());
  EXPECT_EQ(codec.decode_pose({bytes, bytes + scaled->GetPackSize()}, pose), Verdict::malformed);
  igtl::IdentityMatrix(matrix);
  matrix[1][3] = std::numeric_limits<float>::quiet_NaN();
  scaled->SetMatrix(matrix);
  scaled->Pack();
  bytes = static_cast<const std::uint8_t*>(scaled->GetPackPointer());
  EXPECT_EQ(codec.decode_pose({bytes, bytes + scaled->GetPackSize()}, pose), Verdict::malformed);
  DevicePose zero_quaternion = example_pose();
  zero_quaternion.orientation_wxyz = {0.0, 0.0, 0.0, 0.0};
  EXPECT_EQ(codec.decode_pose(test::pack_position("ProbeToTissue", zero_quaternion), pose), Verdict::malformed);

  EXPECT_EQ(codec.decode_pose(test::pack_transform("NeedleToTracker", example_pose()), pose), Verdict::ignored);
  std::vector<std::uint8_t> other = good;  // the same bytes as another type
  std::memcpy(other.data() + 2, "STRING\0\0\0\0\0\0", 12);
  EXPECT_EQ(codec.decode_pose(other, pose), Verdict::ignored);
  // None of them touched the pose.
  EXPECT_EQ(pose.position_m, untouched.position_m);
  EXPECT_EQ(pose.orientation_wxyz, untouched.orientation_wxyz);
}

TEST(IgtlCodec, TheForceIsASensorMessageInNewtons) {
  Codec codec(CodecSettings{});
  std::vector<std::uint8_t> bytes;
  codec.append_force({0.25, -1.5, 3.125}, bytes);
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  header->InitPack();
  std::memcpy(header->GetPackPointer(), bytes.data(), igtl_link::HEADER_SIZE);
  header->Unpack();
  EXPECT_STREQ(header->GetDeviceType(), "SENSOR");
  EXPECT_STREQ(header->GetDeviceName(), "TissueForce");
  igtl::SensorMessage::Pointer sensor = igtl::SensorMessage::New();
  sensor->SetMessageHeader(header);
  sensor->AllocatePack();
  ASSERT_EQ(bytes.size(), igtl_link::HEADER_SIZE + static_cast<std::size_t>(sensor->GetPackBodySize()));
  std::memcpy(sensor->GetPackBodyPointer(), bytes.data() + igtl_link::HEADER_SIZE,
              bytes.size() - igtl_link::HEADER_SIZE);
  ASSERT_NE(sensor->Unpack(1) & igtl::MessageBase::UNPACK_BODY, 0);
  ASSERT_EQ(sensor->GetLength(), 3u);
  EXPECT_EQ(sensor->GetValue(0), 0.25);  // float64 on the wire: exact
  EXPECT_EQ(sensor->GetValue(1), -1.5);
  EXPECT_EQ(sensor->GetValue(2), 3.125);
  igtl::Unit::Pointer newton = igtl::Unit::New();
  newton->Init();
  newton->Append(IGTL_UNIT_SI_DERIVED_NEWTON, 1);
  EXPECT_EQ(sensor->GetUnit(), newton->Pack());
}

TEST(IgtlCodec, TheSurfaceIsPolyDataOfTheUsedPointsInTheWireUnit) {
  SurfaceFrame frame;
  // Five vertices, the third used by no triangle (an interior vertex); a mesh face and a cut face.
  frame.positions_m = {0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 9.0, 9.0, 9.0, 0.0, 0.01, 0.0, 0.0, 0.0, 0.02};
  frame.triangles = {0, 1, 3, 1, 4, 3};
  frame.mesh_triangle_count = 1;
  Codec codec(CodecSettings{});
  std::vector<std::uint8_t> bytes;
  codec.append_surface(frame, bytes);
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  header->InitPack();
  std::memcpy(header->GetPackPointer(), bytes.data(), igtl_link::HEADER_SIZE);
  header->Unpack();
  EXPECT_STREQ(header->GetDeviceType(), "POLYDATA");
  EXPECT_STREQ(header->GetDeviceName(), "TissueSurface");
  igtl::PolyDataMessage::Pointer poly = igtl::PolyDataMessage::New();
  poly->SetMessageHeader(header);
  poly->AllocatePack();
  ASSERT_EQ(bytes.size(), igtl_link::HEADER_SIZE + static_cast<std::size_t>(poly->GetPackBodySize()));
  std::memcpy(poly->GetPackBodyPointer(), bytes.data() + igtl_link::HEADER_SIZE, bytes.size() - igtl_link::HEADER_SIZE);
  ASSERT_NE(poly->Unpack(1) & igtl::MessageBase::UNPACK_BODY, 0);
  ASSERT_EQ(poly->GetPoints()->GetNumberOfPoints(), 4);
  std::array<igtlFloat32, 3> p{};
  poly->GetPoints()->GetPoint(1, p.data());  // the second point used: vertex 1, (10, 0, 0) mm
  EXPECT_EQ(p, (std::array<igtlFloat32, 3>{10.0F, 0.0F, 0.0F}));
  poly->GetPoints()->GetPoint(3, p.data());  // vertex 4, (0, 0, 20) mm
  EXPECT_EQ(p, (std::array<igtlFloat32, 3>{0.0F, 0.0F, 20.0F}));
  ASSERT_EQ(poly->GetPolygons()->GetNumberOfCells(), 2u);
  std::array<igtlUint32, 3> cell{};
  poly->GetPolygons()->GetCell(1, cell.data());
  EXPECT_EQ(cell, (std::array<igtlUint32, 3>{1, 3, 2}));  // vertices 1 4 3 renumbered
}

TEST(IgtlCodec, SettingsTheWireCannotCarryAreRefused) {
  CodecSettings long_name;
  long_name.probe_transform = "AVeryLongTransformNameIndeed";  // 28 > 20 characters
  EXPECT_THROW(Codec{long_name}, std::invalid_argument);
  CodecSettings same;
  same.scalpel_transform = same.probe_transform;
  EXPECT_THROW(Codec{same}, std::invalid_argument);
  CodecSettings no_unit;
  no_unit.length_unit_m = 0.0;
  EXPECT_THROW(Codec{no_unit}, std::invalid_argument);
}

// --- the server and the device over loopback ---

IgtlServerSettings ephemeral() {
  IgtlServerSettings settings;
  settings.port = 0;
  return settings;
}

// Reads the device (session time fixed) until a pose accepted since the last call shows up.
bool wait_for_pose(IgtlDevice& device, std::uint64_t accepted_before, IgtlServer& server, double time_s,
                   DevicePose& pose) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < give_up) {
    pose = device.read(time_s);
    if (server.counters().accepted > accepted_before && device.counters().accepted > accepted_before) {
      pose = device.read(time_s);
      return true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

// Waits until the server has counted @p received messages.
bool wait_for_received(const IgtlServer& server, std::uint64_t received) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (server.counters().received < received) {
    if (std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

TEST(IgtlDevice, PosesComeInForcesGoBackAndBadMessagesAreCountedAndChangeNothing) {
  auto server = std::make_shared<IgtlServer>(ephemeral());
  IgtlDevice device(server, ForceWatchdogSettings{0.050, 0.0});
  test::IgtlClient client("127.0.0.1", server->port());
  DevicePose pose;
  EXPECT_EQ(device.write_force(0.0, {1.0, 2.0, 3.0}), (std::array<double, 3>{0.0, 0.0, 0.0}))
      << "no force before the first pose";

  const std::uint64_t t0 = 1000ULL << 32U;  // the client's timestamps: seconds << 32
  client.send_transform("ProbeToTissue", example_pose(), 1e-3, t0);
  ASSERT_TRUE(wait_for_pose(device, 0, *server, 0.001, pose));
  expect_pose(pose, example_pose());
  const std::array<double, 3> sent = device.write_force(0.001, {0.5, -0.25, 2.0});
  EXPECT_EQ(sent, (std::array<double, 3>{0.5, -0.25, 2.0}));
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (client.forces().empty() && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_FALSE(client.forces().empty());
  EXPECT_EQ(client.forces().back().force_n, sent);
  EXPECT_TRUE(client.forces().back().unit_is_newton);

  // Bad messages, each with a pose far from the good one: none may move the tool.
  DevicePose far = example_pose();
  far.position_m = {0.5, 0.5, 0.5};
  std::vector<std::uint8_t> corrupted = test::pack_transform("ProbeToTissue", far, 1e-3, t0 + 10);
  corrupted.back() ^= 0x01U;
  client.send_raw(corrupted);                                    // malformed (CRC)
  client.send_transform("ProbeToTissue", far, 1e-3, t0 - 1);     // out of order
  client.send_transform("ProbeToTissue", far, 1e-3, t0);         // duplicate
  client.send_transform("NeedleToTracker", far, 1e-3, t0 + 20);  // ignored
  std::vector<std::uint8_t> oversized = test::pack_transform("ProbeToTissue", far, 1e-3, t0 + 30);
  const std::uint64_t big_body = 100000;  // > 65536: skipped unread
  for (int i = 0; i < 8; ++i) oversized[42 + i] = static_cast<std::uint8_t>(big_body >> (8U * (7 - i)));
  oversized.resize(igtl_link::HEADER_SIZE + big_body, 0xEE);
  client.send_raw(oversized);  // oversized
  ASSERT_TRUE(wait_for_received(*server, 6));
  for (int k = 0; k < 5; ++k) pose = device.read(0.002);
  expect_pose(pose, example_pose());  // still the good pose

  // The stream is still in step after the skipped body: the next good pose arrives.
  DevicePose next = example_pose();
  next.position_m[2] += 0.001;
  client.send_transform("ProbeToTissue", next, 1e-3, t0 + 40);
  ASSERT_TRUE(wait_for_pose(device, 1, *server, 0.003, pose));
  expect_pose(pose, next);

  const DeviceCounters c = device.counters();
  EXPECT_EQ(c.received, 7u);
  EXPECT_EQ(c.accepted, 2u);
  EXPECT_EQ(c.malformed, 1u);
  EXPECT_EQ(c.out_of_order, 1u);
  EXPECT_EQ(c.duplicate, 1u);
  EXPECT_EQ(c.ignored, 1u);
  EXPECT_EQ(c.oversized, 1u);
  EXPECT_EQ(c.received, c.accepted + c.malformed + c.oversized + c.out_of_order + c.duplicate + c.ignored + c.stale);
}

TEST(IgtlServer, OneClientAtATimeAndAnotherOnceItLeaves) {
  auto server = std::make_shared<IgtlServer>(ephemeral());
  auto first = std::make_unique<test::IgtlClient>("127.0.0.1", server->port());
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (server->counters().connections < 1 && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  {
    test::IgtlClient second("127.0.0.1", server->port());
    while (server->counters().refused_connections < 1 && std::chrono::steady_clock::now() < give_up) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    EXPECT_EQ(server->counters().refused_connections, 1u);
  }
  first.reset();
  IgtlDevice device(server);
  test::IgtlClient third("127.0.0.1", server->port());
  third.send_transform("ProbeToTissue", example_pose());
  DevicePose pose;
  ASSERT_TRUE(wait_for_pose(device, 0, *server, 0.0, pose)) << "the server did not take a client after the first left";
  expect_pose(pose, example_pose());
  EXPECT_EQ(server->counters().connections, 2u);
}

TEST(IgtlServer, ListensOnLoopbackOnlyUnlessAskedAndRefusesBadSettings) {
  IgtlServerSettings remote = ephemeral();
  remote.address = "0.0.0.0";
  try {
    IgtlServer server(remote);
    ADD_FAILURE() << "0.0.0.0 was accepted without allow_remote";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a loopback address"), std::string::npos) << e.what();
  }
  remote.allow_remote = true;
  EXPECT_NO_THROW(IgtlServer{remote});
  IgtlServerSettings bad = ephemeral();
  bad.surface_rate_hz = -1.0;
  EXPECT_THROW(IgtlServer{bad}, std::runtime_error);
  IgtlServer first(ephemeral());
  IgtlServerSettings busy = ephemeral();
  busy.port = first.port();
  try {
    IgtlServer second(busy);
    ADD_FAILURE() << "a busy port was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot listen on tcp 127.0.0.1:" + std::to_string(first.port())),
              std::string::npos)
        << e.what();
  }
}

// The force after the client went silent for 200 ms of session time (poses at 0..10 ms).
std::array<double, 3> force_after_silence(const ForceWatchdogSettings& watchdog) {
  auto server = std::make_shared<IgtlServer>(ephemeral());
  IgtlDevice device(server, watchdog);
  test::IgtlClient client("127.0.0.1", server->port());
  client.send_transform("ProbeToTissue", example_pose());
  DevicePose pose;
  if (!wait_for_pose(device, 0, *server, 0.0, pose)) return {NAN, NAN, NAN};
  for (int tick = 0; tick <= 10; ++tick) device.write_force(1e-3 * tick, {0.0, 0.0, 2.0});
  for (int tick = 11; tick <= 210; ++tick) {
    device.read(1e-3 * tick);
    device.write_force(1e-3 * tick, {0.0, 0.0, 2.0});
  }
  return device.write_force(0.210, {0.0, 0.0, 2.0});
}

TEST(IgtlDevice, SilenceZeroesTheForceWhichWithoutTheWatchdogWouldStay) {
  // Timeout 50 ms, ramp 100 ms: zero from 150 ms after the last pose.
  const std::array<double, 3> guarded = force_after_silence(ForceWatchdogSettings{0.050, 0.100});
  EXPECT_EQ(guarded, (std::array<double, 3>{0.0, 0.0, 0.0}));
  // The same silence with the watchdog switched off: the full force is still pushed at the hand.
  const std::array<double, 3> unguarded =
      force_after_silence(ForceWatchdogSettings{std::numeric_limits<double>::infinity(), 0.100});
  EXPECT_EQ(unguarded, (std::array<double, 3>{0.0, 0.0, 2.0}));
}

}  // namespace
}  // namespace tissue::host
