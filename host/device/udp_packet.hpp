// udp_packet.hpp - the wire format of the UDP device bridge (device/UDP_PROTOCOL.md): pose
// packets from a driver process to tissue-host, force packets back.
//
// Shared by UdpDevice and by drivers written in C++ (tests/host/udp_sender.* is one). All
// fields are little-endian; doubles are IEEE-754 binary64. Every packet is a 32-byte header, a
// fixed payload per type and a CRC-32 (the zlib/IEEE 802.3 polynomial) of all preceding bytes.
// Encoding writes whatever it is given (a test can build a packet with a NaN in it); decoding
// checks everything and says why a datagram is refused. No function here allocates or throws.
#pragma once

#include "device/device.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace tissue::host::udp {

inline constexpr std::array<std::uint8_t, 4> MAGIC{'T', 'S', 'U', 'D'};
inline constexpr std::uint16_t PROTOCOL_VERSION = 1;
/// The port UdpDevice listens on unless told otherwise.
inline constexpr std::uint16_t DEFAULT_PORT = 47001;

enum class PacketType : std::uint16_t { pose = 1, force = 2 };

inline constexpr std::size_t HEADER_SIZE = 32;
inline constexpr std::size_t CHECKSUM_SIZE = 4;
/// Header, position [3] and orientation [4] (f64), tool mode and reserved (u32), checksum.
inline constexpr std::size_t POSE_PACKET_SIZE = 100;
/// Header, force [3] and scale (f64), ack sequence (u64), checksum.
inline constexpr std::size_t FORCE_PACKET_SIZE = 76;
/// A quaternion whose squared norm is below this is "zero" and refused.
inline constexpr double MIN_QUATERNION_NORM_SQUARED = 1e-12;

/// Driver -> host, at up to 1 kHz: the hand at the sender's time.
struct PosePacket {
  std::uint64_t sequence = 0;  ///< strictly increasing per stream, starting at 1 (0 is refused)
  double send_time_s = 0.0;    ///< the sender's monotonic clock; any epoch, never synchronized
  DevicePose pose;             ///< orientation as sent (decode does not normalize it)
};

/// Host -> driver, once per haptic tick: the force to render on the hand.
struct ForcePacket {
  std::uint64_t sequence = 0;       ///< the host's own strictly increasing sequence, from 1
  double send_time_s = 0.0;         ///< the host's session time
  std::array<double, 3> force_n{};  ///< already scaled by watchdog_scale
  double watchdog_scale = 0.0;      ///< 1: tracking; ramps to 0 when the poses stop
  std::uint64_t ack_sequence = 0;   ///< sequence of the newest accepted pose packet (0: none yet)
};

/// Why decode_*() refused a datagram (all count as "malformed" in DeviceCounters).
enum class DecodeError : std::uint8_t {
  none = 0,
  wrong_size,         ///< datagram size is not the type's size, or too short for a header
  bad_magic,          ///< first four bytes are not "TSUD"
  bad_version,        ///< version is not PROTOCOL_VERSION
  wrong_type,         ///< not the packet type asked for (or an unknown type)
  bad_length,         ///< the header's length field differs from the datagram size
  bad_checksum,       ///< CRC-32 mismatch
  nonzero_reserved,   ///< a reserved field is not zero
  zero_sequence,      ///< sequence 0
  non_finite,         ///< a NaN or infinite time, position, quaternion, force or scale
  zero_quaternion,    ///< orientation with squared norm < MIN_QUATERNION_NORM_SQUARED
  unknown_tool_mode,  ///< tool mode not 0, 1 or 2
  scale_out_of_range  ///< force packet watchdog_scale outside [0, 1]
};

/// Name of a DecodeError, for messages and test output.
[[nodiscard]] const char* decode_error_name(DecodeError error);

/// CRC-32/ISO-HDLC (zlib's crc32(), Python's zlib.crc32): reflected polynomial 0xEDB88320,
/// initial value and final xor 0xFFFFFFFF. crc32("123456789") == 0xCBF43926.
[[nodiscard]] std::uint32_t crc32(std::span<const std::uint8_t> bytes);

/// Computes the CRC-32 of packet[0, size - 4) and stores it little-endian in the last 4 bytes.
/// For building test packets; encode_*() already do this. No-op if the packet is shorter than 4.
void write_checksum(std::span<std::uint8_t> packet);

[[nodiscard]] std::array<std::uint8_t, POSE_PACKET_SIZE> encode_pose(const PosePacket& packet);
[[nodiscard]] std::array<std::uint8_t, FORCE_PACKET_SIZE> encode_force(const ForcePacket& packet);

/// Decodes and validates one datagram; @p out is written only when the result is DecodeError::none.
[[nodiscard]] DecodeError decode_pose(std::span<const std::uint8_t> datagram, PosePacket& out);
[[nodiscard]] DecodeError decode_force(std::span<const std::uint8_t> datagram, ForcePacket& out);

}  // namespace tissue::host::udp
