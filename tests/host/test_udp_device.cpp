// test_udp_device.cpp - the UDP device bridge (host/device/udp_*): the packet format against
// UDP_PROTOCOL.md, and UdpDevice over real loopback sockets driven by UdpSender: round trip,
// every drop reason with exact counts, the stale check, the watchdog ramp (session time passed
// explicitly, no sleeping), the loopback-only rule and no allocation in read()/write_force().
#include "support/counting_new.hpp"
#include "udp_sender.hpp"

#include "device/udp_device.hpp"
#include "device/udp_packet.hpp"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace tissue::host {
namespace {

using test::UdpSender;
constexpr double NAN_VALUE = std::numeric_limits<double>::quiet_NaN();
constexpr double TICK_S = 1e-3;

udp::PosePacket pose_packet(std::uint64_t sequence, double x, double send_time_s = 0.0) {
  udp::PosePacket p;
  p.sequence = sequence;
  p.send_time_s = send_time_s;
  p.pose.position_m = {x, -0.25, 0.125};
  p.pose.orientation_wxyz = {0.5, 0.5, -0.5, 0.5};
  p.pose.mode = ToolMode::scalpel;
  return p;
}

void expect_consistent(const DeviceCounters& c) {
  EXPECT_EQ(c.received, c.accepted + c.malformed + c.out_of_order + c.duplicate + c.stale);
}

// read() at @p time_s until the device has received @p received datagrams in all (loopback
// delivery is fast but not synchronous with sendto); repeated reads at one time are idempotent.
DevicePose read_until(UdpDevice& device, double time_s, std::uint64_t received) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  DevicePose pose = device.read(time_s);
  while (device.counters().received < received) {
    if (std::chrono::steady_clock::now() > deadline) {
      ADD_FAILURE() << "the device received " << device.counters().received << " of " << received << " datagrams";
      break;
    }
    pose = device.read(time_s);
  }
  return pose;
}

UdpDeviceSettings ephemeral() {
  UdpDeviceSettings s;
  s.port = 0;
  return s;
}

// ---------------------------------------------------------------------------------------------
// The packet format

TEST(UdpPacket, Crc32IsZlibCrc32) {
  const std::string check = "123456789";
  EXPECT_EQ(udp::crc32({reinterpret_cast<const std::uint8_t*>(check.data()), check.size()}), 0xCBF43926U);
  EXPECT_EQ(udp::crc32({}), 0U);
}

TEST(UdpPacket, PoseLayoutAndRoundTrip) {
  const udp::PosePacket sent = pose_packet(0x0102030405060708ULL, 0.0625, 1234.5);
  const auto bytes = udp::encode_pose(sent);
  ASSERT_EQ(bytes.size(), 100U);
  // UDP_PROTOCOL.md: magic, version 1, type 1, length 100, little-endian.
  EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 4), "TSUD");
  EXPECT_EQ(bytes[4], 1);
  EXPECT_EQ(bytes[5], 0);
  EXPECT_EQ(bytes[6], 1);
  EXPECT_EQ(bytes[8], 100);
  EXPECT_EQ(bytes[16], 0x08);
  EXPECT_EQ(bytes[23], 0x01);
  std::uint64_t bits = 0;
  for (int i = 7; i >= 0; --i) bits = (bits << 8U) | bytes[32 + static_cast<std::size_t>(i)];
  EXPECT_EQ(std::bit_cast<double>(bits), 0.0625);  // position x at offset 32
  EXPECT_EQ(bytes[88], 2);                         // tool mode at offset 88
  const std::uint32_t crc = udp::crc32({bytes.data(), 96});
  EXPECT_EQ(bytes[96], crc & 0xFFU);
  EXPECT_EQ(bytes[99], crc >> 24U);

  udp::PosePacket got;
  ASSERT_EQ(udp::decode_pose(bytes, got), udp::DecodeError::none);
  EXPECT_EQ(got.sequence, sent.sequence);
  EXPECT_EQ(got.send_time_s, sent.send_time_s);
  EXPECT_EQ(got.pose.position_m, sent.pose.position_m);
  EXPECT_EQ(got.pose.orientation_wxyz, sent.pose.orientation_wxyz);
  EXPECT_EQ(got.pose.mode, sent.pose.mode);
}

TEST(UdpPacket, ForceLayoutAndRoundTrip) {
  udp::ForcePacket sent;
  sent.sequence = 77;
  sent.send_time_s = 3.25;
  sent.force_n = {1.5, -2.0, 1e-300};
  sent.watchdog_scale = 0.375;
  sent.ack_sequence = 0xAABBCCDDEEFF0011ULL;
  const auto bytes = udp::encode_force(sent);
  ASSERT_EQ(bytes.size(), 76U);
  EXPECT_EQ(bytes[6], 2);
  EXPECT_EQ(bytes[8], 76);
  EXPECT_EQ(bytes[64], 0x11);  // ack_sequence at offset 64
  udp::ForcePacket got;
  ASSERT_EQ(udp::decode_force(bytes, got), udp::DecodeError::none);
  EXPECT_EQ(got.sequence, 77U);
  EXPECT_EQ(got.send_time_s, 3.25);
  EXPECT_EQ(got.force_n, sent.force_n);
  EXPECT_EQ(got.watchdog_scale, 0.375);
  EXPECT_EQ(got.ack_sequence, sent.ack_sequence);
  // A pose decoder refuses a force packet and the reverse.
  udp::PosePacket pose;
  EXPECT_EQ(udp::decode_pose(bytes, pose), udp::DecodeError::wrong_type);
  EXPECT_EQ(udp::decode_force(udp::encode_pose(pose_packet(1, 0.0)), got), udp::DecodeError::wrong_type);
}

TEST(UdpPacket, ChecksumCatchesEveryFlippedBit) {
  const auto good = udp::encode_pose(pose_packet(9, 0.01, 2.0));
  int caught = 0;
  for (std::size_t bit = 0; bit < 8 * good.size(); ++bit) {
    auto bad = good;
    bad[bit / 8] = static_cast<std::uint8_t>(bad[bit / 8] ^ (1U << (bit % 8)));
    udp::PosePacket out;
    const udp::DecodeError e = udp::decode_pose(bad, out);
    // Magic, version, type and length are checked before the checksum and may refuse first.
    if (bit / 8 >= 12) {
      EXPECT_EQ(e, udp::DecodeError::bad_checksum) << "bit " << bit;
    } else {
      EXPECT_NE(e, udp::DecodeError::none) << "bit " << bit;
    }
    caught += e != udp::DecodeError::none ? 1 : 0;
  }
  EXPECT_EQ(caught, 800);
}

TEST(UdpPacket, DecodeNamesWhyItRefuses) {
  const udp::PosePacket base = pose_packet(3, 0.02, 5.0);
  struct Case {
    const char* what;
    std::vector<std::uint8_t> bytes;
    udp::DecodeError expected;
  };
  const auto encoded = [](const udp::PosePacket& p) {
    const auto a = udp::encode_pose(p);
    return std::vector<std::uint8_t>(a.begin(), a.end());
  };
  const auto resealed = [&](auto mutate) {
    std::vector<std::uint8_t> b = encoded(base);
    mutate(b);
    udp::write_checksum(b);
    return b;
  };
  const std::vector<std::uint8_t> full = encoded(base);
  udp::PosePacket p = base;
  std::vector<Case> cases;
  cases.push_back({"empty", {}, udp::DecodeError::wrong_size});
  cases.push_back(
      {"header only", std::vector<std::uint8_t>(full.begin(), full.begin() + 20), udp::DecodeError::wrong_size});
  cases.push_back(
      {"truncated", std::vector<std::uint8_t>(full.begin(), full.begin() + 60), udp::DecodeError::bad_length});
  cases.push_back({"magic", resealed([](auto& b) { b[0] = 'X'; }), udp::DecodeError::bad_magic});
  cases.push_back({"version", resealed([](auto& b) { b[4] = 2; }), udp::DecodeError::bad_version});
  cases.push_back({"type", resealed([](auto& b) { b[6] = 9; }), udp::DecodeError::wrong_type});
  cases.push_back({"length field", resealed([](auto& b) { b[8] = 99; }), udp::DecodeError::bad_length});
  {
    std::vector<std::uint8_t> huge = encoded(base);  // a valid packet followed by padding
    huge.resize(1500, 0xAB);
    cases.push_back({"huge", huge, udp::DecodeError::bad_length});
  }
  {
    std::vector<std::uint8_t> b = encoded(base);
    b[40] ^= 0x10U;
    cases.push_back({"checksum", b, udp::DecodeError::bad_checksum});
  }
  cases.push_back({"reserved", resealed([](auto& b) { b[12] = 1; }), udp::DecodeError::nonzero_reserved});
  cases.push_back({"pose reserved", resealed([](auto& b) { b[95] = 1; }), udp::DecodeError::nonzero_reserved});
  p = base;
  p.sequence = 0;
  cases.push_back({"sequence 0", encoded(p), udp::DecodeError::zero_sequence});
  p = base;
  p.pose.position_m[1] = NAN_VALUE;
  cases.push_back({"NaN position", encoded(p), udp::DecodeError::non_finite});
  p = base;
  p.send_time_s = std::numeric_limits<double>::infinity();
  cases.push_back({"infinite time", encoded(p), udp::DecodeError::non_finite});
  p = base;
  p.pose.orientation_wxyz = {1.0, NAN_VALUE, 0.0, 0.0};
  cases.push_back({"NaN quaternion", encoded(p), udp::DecodeError::non_finite});
  p = base;
  p.pose.orientation_wxyz = {1e200, 0.0, 0.0, 0.0};
  cases.push_back({"overflowing quaternion", encoded(p), udp::DecodeError::non_finite});
  p = base;
  p.pose.orientation_wxyz = {0.0, 0.0, 0.0, 0.0};
  cases.push_back({"zero quaternion", encoded(p), udp::DecodeError::zero_quaternion});
  p = base;
  p.pose.mode = static_cast<ToolMode>(3);
  cases.push_back({"tool mode 3", encoded(p), udp::DecodeError::unknown_tool_mode});

  for (const Case& c : cases) {
    udp::PosePacket out = pose_packet(42, 42.0);
    EXPECT_EQ(udp::decode_pose(c.bytes, out), c.expected)
        << c.what << ": got " << udp::decode_error_name(udp::decode_pose(c.bytes, out));
    EXPECT_EQ(out.sequence, 42U) << c.what << ": a refused packet must not be written";
  }
}

// ---------------------------------------------------------------------------------------------
// UdpDevice over loopback

TEST(UdpDevice, LoopbackRoundTrip) {
  UdpDeviceSettings settings = ephemeral();
  settings.ramp_time_s = 0.0;  // full force at once: this test checks values, not the ramp
  UdpDevice device(settings);
  ASSERT_NE(device.local_port(), 0);
  EXPECT_EQ(device.name(), "udp 127.0.0.1:" + std::to_string(device.local_port()));
  UdpSender sender("127.0.0.1", device.local_port());

  DevicePose pose;
  const double c = std::cos(0.3);
  const double s = std::sin(0.3);
  for (int i = 1; i <= 3; ++i) {
    pose.position_m = {0.01 * i, -0.02, 0.003};
    pose.orientation_wxyz = {2.0 * c, 0.0, 2.0 * s, 0.0};  // read() normalizes
    pose.mode = i == 3 ? ToolMode::probe : ToolMode::scalpel;
    EXPECT_EQ(sender.send_pose(pose, 100.0 + 0.001 * i), static_cast<std::uint64_t>(i));
  }
  const DevicePose got = read_until(device, 0.5, 3);
  EXPECT_EQ(got.position_m, pose.position_m);
  const std::array<double, 4> unit{c, 0.0, s, 0.0};
  for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(got.orientation_wxyz[k], unit[k], 1e-15);
  EXPECT_EQ(got.mode, ToolMode::probe);
  const DeviceCounters counts = device.counters();
  EXPECT_EQ(counts.received, 3U);
  EXPECT_EQ(counts.accepted, 3U);
  expect_consistent(counts);

  // The held pose is returned while nothing new arrives.
  EXPECT_EQ(device.read(0.501).position_m, pose.position_m);

  const std::array<double, 3> commanded{1.25, -2.5, 0.75};
  EXPECT_EQ(device.write_force(0.502, commanded), commanded);
  const std::optional<udp::ForcePacket> force = sender.receive_force(1.0);
  ASSERT_TRUE(force.has_value());
  EXPECT_EQ(force->sequence, 1U);
  EXPECT_EQ(force->send_time_s, 0.502);
  EXPECT_EQ(force->force_n, commanded);
  EXPECT_EQ(force->watchdog_scale, 1.0);
  EXPECT_EQ(force->ack_sequence, 3U);
  device.write_force(0.503, commanded);
  const std::optional<udp::ForcePacket> second = sender.receive_force(1.0);
  ASSERT_TRUE(second.has_value());
  EXPECT_EQ(second->sequence, 2U);
}

TEST(UdpDevice, NoForceBeforeTheFirstPoseAndNonFiniteForceIsZero) {
  UdpDeviceSettings settings = ephemeral();
  settings.ramp_time_s = 0.0;
  UdpDevice device(settings);
  UdpSender sender("127.0.0.1", device.local_port());
  EXPECT_EQ(device.read(0.0).position_m, (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_EQ(device.write_force(0.0, {1.0, 2.0, 3.0}), (std::array<double, 3>{0.0, 0.0, 0.0}));
  EXPECT_FALSE(sender.receive_force(0.02).has_value()) << "nowhere to send before a pose arrived";

  sender.send_pose(DevicePose{}, 1.0);
  read_until(device, 0.001, 1);
  EXPECT_EQ(device.write_force(0.001, {NAN_VALUE, 1.0, 1.0}), (std::array<double, 3>{0.0, 0.0, 0.0}));
  const std::optional<udp::ForcePacket> force = sender.receive_force(1.0);
  ASSERT_TRUE(force.has_value());
  EXPECT_EQ(force->force_n, (std::array<double, 3>{0.0, 0.0, 0.0}));
}

TEST(UdpDevice, MalformedPacketsAreDroppedAndCounted) {
  UdpDevice device(ephemeral());
  UdpSender sender("127.0.0.1", device.local_port());
  sender.send_packet(pose_packet(5, 0.005));
  read_until(device, 0.0, 1);

  // Each of these carries sequence 100: had one been taken, sequence 6 below would be out of order.
  const auto bytes = [](const udp::PosePacket& p) { return udp::encode_pose(p); };
  const udp::PosePacket later = pose_packet(100, 1.0);
  auto truncated = bytes(later);
  sender.send_raw(std::span<const std::uint8_t>(truncated.data(), 50));
  auto magic = bytes(later);
  magic[1] = 'X';
  udp::write_checksum(magic);
  sender.send_raw(magic);
  auto flipped = bytes(later);
  flipped[33] ^= 0x04U;
  sender.send_raw(flipped);
  udp::PosePacket nan_position = later;
  nan_position.pose.position_m[2] = NAN_VALUE;
  sender.send_packet(nan_position);
  std::vector<std::uint8_t> huge(9000, 0);  // larger than the device's receive buffer
  std::memcpy(huge.data(), bytes(later).data(), udp::POSE_PACKET_SIZE);
  sender.send_raw(huge);
  std::vector<std::uint8_t> padded(300, 0);  // fits the buffer, valid packet in front
  std::memcpy(padded.data(), bytes(later).data(), udp::POSE_PACKET_SIZE);
  sender.send_raw(padded);
  sender.send_raw({});
  udp::PosePacket zero_quaternion = later;
  zero_quaternion.pose.orientation_wxyz = {0.0, 0.0, 0.0, 0.0};
  sender.send_packet(zero_quaternion);
  udp::PosePacket bad_mode = later;
  bad_mode.pose.mode = static_cast<ToolMode>(7);
  sender.send_packet(bad_mode);
  udp::ForcePacket force;
  force.sequence = 100;
  sender.send_raw(udp::encode_force(force));
  constexpr std::uint64_t MALFORMED = 10;

  sender.send_packet(pose_packet(6, 0.006));
  const DevicePose pose = read_until(device, 0.001, 1 + MALFORMED + 1);
  EXPECT_EQ(pose.position_m[0], 0.006);
  const DeviceCounters c = device.counters();
  EXPECT_EQ(c.received, 12U);
  EXPECT_EQ(c.malformed, MALFORMED);
  EXPECT_EQ(c.accepted, 2U);
  EXPECT_EQ(c.out_of_order, 0U);
  EXPECT_EQ(c.duplicate, 0U);
  EXPECT_EQ(c.stale, 0U);
  expect_consistent(c);
}

TEST(UdpDevice, OutOfOrderAndReplayedPacketsAreDroppedAndCounted) {
  UdpDevice device(ephemeral());
  UdpSender sender("127.0.0.1", device.local_port());
  // Position x tells which packet the device kept: 1, 2, 5, 6 are taken in that order.
  const std::array<std::uint64_t, 9> sequences{1, 2, 5, 3, 5, 4, 6, 6, 6};
  for (std::size_t i = 0; i < sequences.size(); ++i) {
    sender.send_packet(pose_packet(sequences[i], static_cast<double>(sequences[i]) + 0.1 * static_cast<double>(i)));
  }
  const DevicePose pose = read_until(device, 0.0, sequences.size());
  EXPECT_DOUBLE_EQ(pose.position_m[0], 6.6);  // the first 6 (index 6), not its replay
  const DeviceCounters c = device.counters();
  EXPECT_EQ(c.received, 9U);
  EXPECT_EQ(c.accepted, 4U);
  EXPECT_EQ(c.out_of_order, 2U);  // 3 and 4 after 5
  EXPECT_EQ(c.duplicate, 3U);     // 5 once and 6 twice replayed
  EXPECT_EQ(c.malformed, 0U);
  EXPECT_EQ(c.stale, 0U);
  expect_consistent(c);

  const std::array<double, 3> f{0.0, 0.0, 1.0};
  device.write_force(0.0, f);
  const std::optional<udp::ForcePacket> force = sender.receive_force(1.0);
  ASSERT_TRUE(force.has_value());
  EXPECT_EQ(force->ack_sequence, 6U);
}

TEST(UdpDevice, StalePacketsAreDroppedAndCounted) {
  UdpDevice device(ephemeral());  // stale window 20 ms
  UdpSender sender("127.0.0.1", device.local_port());
  // The sender's clock reads 1000 s when the session clock reads 0: the offset itself is
  // irrelevant, only its growth beyond the smallest one seen.
  struct Step {
    std::uint64_t sequence;
    double age_s;  // how much older than on time the packet claims to be
    bool accepted;
  };
  const std::array<Step, 6> steps{{{1, 0.0, true},
                                   {2, 0.0, true},
                                   {3, 0.030, false},
                                   {4, 0.015, true},
                                   {5, 0.025, false},
                                   {5, 0.0, true}}};  // a stale packet does not use up its sequence
  std::uint64_t accepted = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const double t = TICK_S * static_cast<double>(i);
    sender.send_packet(pose_packet(steps[i].sequence, static_cast<double>(i), 1000.0 + t - steps[i].age_s));
    const DevicePose pose = read_until(device, t, i + 1);
    accepted += steps[i].accepted ? 1 : 0;
    EXPECT_EQ(device.counters().accepted, accepted) << "step " << i;
    if (steps[i].accepted) {
      EXPECT_EQ(pose.position_m[0], static_cast<double>(i)) << "step " << i;
    }
  }
  const DeviceCounters c = device.counters();
  EXPECT_EQ(c.received, 6U);
  EXPECT_EQ(c.accepted, 4U);
  EXPECT_EQ(c.stale, 2U);
  EXPECT_EQ(c.duplicate, 0U);
  EXPECT_EQ(c.out_of_order, 0U);
  expect_consistent(c);
}

TEST(UdpDevice, DelayFloorFollowsSlowClockDrift) {
  UdpDeviceSettings settings = ephemeral();
  settings.delay_floor_period_s = 1.0;
  settings.watchdog_timeout_s = 1.0;
  UdpDevice device(settings);
  UdpSender sender("127.0.0.1", device.local_port());
  // The sender's clock runs 0.5% slow: over 6 s the apparent delay grows by 30 ms, past the
  // 20 ms window; a floor kept forever would call everything after 4 s stale.
  std::uint64_t sequence = 0;
  for (int i = 0; i <= 60; ++i) {
    const double t = 0.1 * i;
    sender.send_packet(pose_packet(++sequence, t, 0.995 * t));
    read_until(device, t, sequence);
  }
  EXPECT_EQ(device.counters().stale, 0U);
  // A packet really delayed by 30 ms is still stale.
  sender.send_packet(pose_packet(++sequence, 0.0, 0.995 * 6.1 - 0.030));
  read_until(device, 6.1, sequence);
  EXPECT_EQ(device.counters().stale, 1U);
  expect_consistent(device.counters());
}

// Sends one pose per tick from @p sender and reads it at session time t.
void connected_tick(UdpDevice& device, UdpSender& sender, double t, std::uint64_t& received) {
  DevicePose pose;
  pose.mode = ToolMode::probe;
  sender.send_pose(pose, 50.0 + t);
  read_until(device, t, ++received);
}

TEST(UdpDevice, SilentSenderForceRampsToZeroAndBackAfterResume) {
  const UdpDeviceSettings settings = ephemeral();  // watchdog 50 ms, ramp 100 ms
  const double timeout = settings.watchdog_timeout_s;
  const double ramp = settings.ramp_time_s;
  UdpDevice device(settings);
  UdpSender sender("127.0.0.1", device.local_port());
  const std::array<double, 3> f{0.5, -1.0, 2.0};
  std::vector<udp::ForcePacket> packets;
  std::uint64_t received = 0;

  // Connect: the force ramps up from zero over the ramp time, never down.
  int k = 0;
  double previous = -1.0;
  for (; k < 150; ++k) {
    const double t = TICK_S * k;
    connected_tick(device, sender, t, received);
    const std::array<double, 3> sent = device.write_force(t, f);
    const double scale = sent[2] / f[2];
    EXPECT_GE(scale, previous) << "t=" << t;
    if (t >= ramp + TICK_S) {
      EXPECT_EQ(sent, f) << "t=" << t;
    }
    previous = scale;
    sender.drain_forces(packets);
  }
  EXPECT_EQ(device.counters().watchdog_trips, 0U);
  const double last_accept = TICK_S * (k - 1);

  // Silence: full force up to the timeout, then non-increasing, exactly zero after the ramp.
  previous = 1.0;
  for (; k < 400; ++k) {
    const double t = TICK_S * k;
    device.read(t);
    const std::array<double, 3> sent = device.write_force(t, f);
    const double scale = sent[2] / f[2];
    EXPECT_EQ(sent[0], scale * f[0]);
    EXPECT_LE(scale, previous) << "t=" << t;
    if (t <= last_accept + timeout - TICK_S / 2) {
      EXPECT_EQ(sent, f) << "t=" << t;
    }
    if (t > last_accept + timeout + TICK_S / 2 && t < last_accept + timeout + ramp - TICK_S / 2) {
      EXPECT_GT(scale, 0.0) << "t=" << t;
      EXPECT_LT(scale, 1.0) << "t=" << t;
    }
    if (t >= last_accept + timeout + ramp + TICK_S) {
      EXPECT_EQ(sent, (std::array<double, 3>{0.0, 0.0, 0.0})) << "t=" << t;
    }
    previous = scale;
    sender.drain_forces(packets);
  }
  EXPECT_EQ(device.counters().watchdog_trips, 1U);
  while (sender.receive_force(0.05)) {
  }
  sender.drain_forces(packets);
  ASSERT_FALSE(packets.empty());
  EXPECT_EQ(packets.back().watchdog_scale, 0.0);
  EXPECT_EQ(packets.back().force_n, (std::array<double, 3>{0.0, 0.0, 0.0}));

  // A restarted driver counts from 1 again: taken as a new stream after the trip, and the force
  // ramps back up over the ramp time, starting from zero, to the restarted driver's address.
  UdpSender restarted("127.0.0.1", device.local_port());
  const int resume = k;
  previous = 0.0;
  for (; k < resume + 120; ++k) {
    const double t = TICK_S * k;
    connected_tick(device, restarted, t, received);
    const std::array<double, 3> sent = device.write_force(t, f);
    const double scale = sent[2] / f[2];
    EXPECT_GE(scale, previous) << "t=" << t;
    if (k == resume + 50) {
      EXPECT_NEAR(scale, 0.5, 1e-9);
    }
    if (k >= resume + 101) {
      EXPECT_EQ(sent, f) << "t=" << t;
    }
    previous = scale;
  }
  EXPECT_EQ(device.counters().watchdog_trips, 1U);
  EXPECT_EQ(device.counters().accepted, received);
  const std::optional<udp::ForcePacket> to_restarted = restarted.receive_force(1.0);
  ASSERT_TRUE(to_restarted.has_value());
  EXPECT_EQ(to_restarted->ack_sequence, 1U);
}

TEST(UdpDevice, LateHostWithAFreshPoseWaitingDoesNotTrip) {
  UdpDeviceSettings settings = ephemeral();
  settings.ramp_time_s = 0.0;
  UdpDevice device(settings);
  UdpSender sender("127.0.0.1", device.local_port());
  const std::array<double, 3> f{0.0, 1.0, 0.0};
  sender.send_packet(pose_packet(1, 1.0, 0.0));
  read_until(device, 0.0, 1);
  EXPECT_EQ(device.write_force(0.0, f), f);
  // The haptic thread stalls for 110 ms (twice the watchdog timeout) while the driver keeps
  // sending: the queued old pose is stale, the fresh one keeps the stream alive.
  sender.send_packet(pose_packet(2, 2.0, 0.050));
  sender.send_packet(pose_packet(3, 3.0, 0.109));
  const DevicePose pose = read_until(device, 0.110, 3);
  EXPECT_EQ(pose.position_m[0], 3.0);
  EXPECT_EQ(device.write_force(0.110, f), f);
  const DeviceCounters c = device.counters();
  EXPECT_EQ(c.watchdog_trips, 0U);
  EXPECT_EQ(c.stale, 1U);
  EXPECT_EQ(c.accepted, 2U);
}

TEST(UdpDevice, RestartedSenderIsOutOfOrderUntilTheWatchdogTrips) {
  UdpDevice device(ephemeral());
  UdpSender first("127.0.0.1", device.local_port());
  for (int i = 0; i < 10; ++i) first.send_pose(DevicePose{}, 1.0);
  read_until(device, 0.0, 10);
  UdpSender second("127.0.0.1", device.local_port());
  second.send_pose(DevicePose{}, 1.0);
  read_until(device, 0.010, 11);
  EXPECT_EQ(device.counters().out_of_order, 1U) << "the first stream is still live";
  device.read(0.061);  // 61 ms of silence: trips
  EXPECT_EQ(device.counters().watchdog_trips, 1U);
  second.send_pose(DevicePose{}, 1.0);
  read_until(device, 0.062, 12);
  EXPECT_EQ(device.counters().accepted, 11U);
  expect_consistent(device.counters());
}

TEST(UdpDevice, RefusesNonLoopbackBindWithoutAllowRemote) {
  for (const char* address : {"0.0.0.0", "192.0.2.1", "::", "2001:db8::1"}) {
    UdpDeviceSettings settings = ephemeral();
    settings.bind_address = address;
    try {
      UdpDevice device(settings);
      ADD_FAILURE() << address << " was accepted";
    } catch (const std::runtime_error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(address), std::string::npos) << message;
      EXPECT_NE(message.find("allow_remote"), std::string::npos) << message;
      EXPECT_NE(message.find("not a loopback address"), std::string::npos) << message;
    }
  }
  UdpDeviceSettings loopback = ephemeral();
  loopback.bind_address = "127.0.0.2";
  EXPECT_NO_THROW(UdpDevice{loopback});
  UdpDeviceSettings remote = ephemeral();
  remote.bind_address = "0.0.0.0";
  remote.allow_remote = true;
  EXPECT_NO_THROW(UdpDevice{remote});
}

TEST(UdpDevice, RefusesBadAddressesBusyPortsAndBadSettings) {
  const auto message_of = [](const UdpDeviceSettings& settings) -> std::string {
    try {
      UdpDevice device(settings);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  UdpDeviceSettings named = ephemeral();
  named.bind_address = "localhost";
  EXPECT_NE(message_of(named).find("not a numeric IPv4 or IPv6 address"), std::string::npos) << message_of(named);

  UdpDevice first(ephemeral());
  UdpDeviceSettings busy = ephemeral();
  busy.port = first.local_port();
  const std::string busy_message = message_of(busy);
  EXPECT_NE(busy_message.find("cannot bind udp 127.0.0.1:" + std::to_string(first.local_port())), std::string::npos)
      << busy_message;

  UdpDeviceSettings bad = ephemeral();
  bad.watchdog_timeout_s = 0.0;
  EXPECT_NE(message_of(bad).find("watchdog_timeout_s"), std::string::npos);
  bad = ephemeral();
  bad.ramp_time_s = NAN_VALUE;
  EXPECT_NE(message_of(bad).find("ramp_time_s"), std::string::npos);
  bad = ephemeral();
  bad.stale_window_s = -1.0;
  EXPECT_NE(message_of(bad).find("stale_window_s"), std::string::npos);
}

TEST(UdpDevice, ReadAndWriteForceDoNotAllocate) {
  UdpDevice device(ephemeral());
  UdpSender sender("127.0.0.1", device.local_port());
  const auto garbage = udp::encode_force(udp::ForcePacket{});
  long allocations = 0;
  std::uint64_t sent = 0;
  for (int k = 0; k < 300; ++k) {
    const double t = TICK_S * k;
    sender.send_pose(DevicePose{}, 7.0 + t);
    sender.send_pose(DevicePose{}, 7.0 + t);
    sender.send_raw(garbage);
    sent += 3;
    const long before = g_allocations.load();
    device.read(t);
    device.write_force(t, {0.0, 0.0, 1.0});
    allocations += g_allocations.load() - before;
    read_until(device, t, sent);  // stay in step with the sender
    while (sender.receive_force(0.0)) {
    }
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(device.counters().accepted, 600U);
  EXPECT_EQ(device.counters().malformed, 300U);
}

}  // namespace
}  // namespace tissue::host
