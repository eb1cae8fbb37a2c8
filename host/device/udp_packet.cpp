// udp_packet.cpp - encoding and validation of the UDP device packets (layout: UDP_PROTOCOL.md).
#include "device/udp_packet.hpp"

#include <bit>
#include <cmath>
#include <optional>

namespace tissue::host::udp {
namespace {

// Byte offsets, UDP_PROTOCOL.md "Header" and "Payloads".
constexpr std::size_t OFFSET_MAGIC = 0;
constexpr std::size_t OFFSET_VERSION = 4;
constexpr std::size_t OFFSET_TYPE = 6;
constexpr std::size_t OFFSET_LENGTH = 8;
constexpr std::size_t OFFSET_HEADER_RESERVED = 12;
constexpr std::size_t OFFSET_SEQUENCE = 16;
constexpr std::size_t OFFSET_SEND_TIME = 24;
constexpr std::size_t OFFSET_POSITION = 32;
constexpr std::size_t OFFSET_ORIENTATION = 56;
constexpr std::size_t OFFSET_TOOL_MODE = 88;
constexpr std::size_t OFFSET_POSE_RESERVED = 92;
constexpr std::size_t OFFSET_FORCE = 32;
constexpr std::size_t OFFSET_SCALE = 56;
constexpr std::size_t OFFSET_ACK = 64;
static_assert(OFFSET_POSE_RESERVED + 4 + CHECKSUM_SIZE == POSE_PACKET_SIZE);
static_assert(OFFSET_ACK + 8 + CHECKSUM_SIZE == FORCE_PACKET_SIZE);

constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1U) : c >> 1U;
    table[i] = c;
  }
  return table;
}
constexpr std::array<std::uint32_t, 256> CRC_TABLE = make_crc_table();

// Little-endian stores and loads, independent of the host's byte order.
template <typename UInt>
void store_le(std::span<std::uint8_t> out, std::size_t offset, UInt value) {
  for (std::size_t i = 0; i < sizeof(UInt); ++i) {
    out[offset + i] = static_cast<std::uint8_t>(value >> (8U * i));
  }
}
template <typename UInt>
UInt load_le(std::span<const std::uint8_t> in, std::size_t offset) {
  UInt value = 0;
  for (std::size_t i = 0; i < sizeof(UInt); ++i) {
    value = static_cast<UInt>(value | static_cast<UInt>(static_cast<UInt>(in[offset + i]) << (8U * i)));
  }
  return value;
}
void store_f64(std::span<std::uint8_t> out, std::size_t offset, double value) {
  store_le(out, offset, std::bit_cast<std::uint64_t>(value));
}
double load_f64(std::span<const std::uint8_t> in, std::size_t offset) {
  return std::bit_cast<double>(load_le<std::uint64_t>(in, offset));
}

void store_header(std::span<std::uint8_t> out, PacketType type, std::uint64_t sequence, double send_time_s) {
  for (std::size_t i = 0; i < MAGIC.size(); ++i) out[OFFSET_MAGIC + i] = MAGIC[i];
  store_le(out, OFFSET_VERSION, PROTOCOL_VERSION);
  store_le(out, OFFSET_TYPE, static_cast<std::uint16_t>(type));
  store_le(out, OFFSET_LENGTH, static_cast<std::uint32_t>(out.size()));
  store_le(out, OFFSET_HEADER_RESERVED, std::uint32_t{0});
  store_le(out, OFFSET_SEQUENCE, sequence);
  store_f64(out, OFFSET_SEND_TIME, send_time_s);
}

// The checks every packet type shares, in the order UDP_PROTOCOL.md lists them.
DecodeError check_header(std::span<const std::uint8_t> in, PacketType type, std::size_t size) {
  if (in.size() < HEADER_SIZE + CHECKSUM_SIZE) return DecodeError::wrong_size;
  for (std::size_t i = 0; i < MAGIC.size(); ++i) {
    if (in[OFFSET_MAGIC + i] != MAGIC[i]) return DecodeError::bad_magic;
  }
  if (load_le<std::uint16_t>(in, OFFSET_VERSION) != PROTOCOL_VERSION) return DecodeError::bad_version;
  if (load_le<std::uint16_t>(in, OFFSET_TYPE) != static_cast<std::uint16_t>(type)) return DecodeError::wrong_type;
  if (load_le<std::uint32_t>(in, OFFSET_LENGTH) != in.size()) return DecodeError::bad_length;
  if (in.size() != size) return DecodeError::wrong_size;
  if (load_le<std::uint32_t>(in, size - CHECKSUM_SIZE) != crc32(in.first(size - CHECKSUM_SIZE))) {
    return DecodeError::bad_checksum;
  }
  if (load_le<std::uint32_t>(in, OFFSET_HEADER_RESERVED) != 0) return DecodeError::nonzero_reserved;
  if (load_le<std::uint64_t>(in, OFFSET_SEQUENCE) == 0) return DecodeError::zero_sequence;
  if (!std::isfinite(load_f64(in, OFFSET_SEND_TIME))) return DecodeError::non_finite;
  return DecodeError::none;
}

}  // namespace

const char* decode_error_name(DecodeError error) {
  switch (error) {
    case DecodeError::none:
      return "none";
    case DecodeError::wrong_size:
      return "wrong_size";
    case DecodeError::bad_magic:
      return "bad_magic";
    case DecodeError::bad_version:
      return "bad_version";
    case DecodeError::wrong_type:
      return "wrong_type";
    case DecodeError::bad_length:
      return "bad_length";
    case DecodeError::bad_checksum:
      return "bad_checksum";
    case DecodeError::nonzero_reserved:
      return "nonzero_reserved";
    case DecodeError::zero_sequence:
      return "zero_sequence";
    case DecodeError::non_finite:
      return "non_finite";
    case DecodeError::zero_quaternion:
      return "zero_quaternion";
    case DecodeError::unknown_tool_mode:
      return "unknown_tool_mode";
    case DecodeError::scale_out_of_range:
      return "scale_out_of_range";
  }
  return "unknown";
}

std::uint32_t crc32(std::span<const std::uint8_t> bytes) {
  std::uint32_t c = 0xFFFFFFFFU;
  for (const std::uint8_t b : bytes) c = CRC_TABLE[(c ^ b) & 0xFFU] ^ (c >> 8U);
  return c ^ 0xFFFFFFFFU;
}

void write_checksum(std::span<std::uint8_t> packet) {
  if (packet.size() < CHECKSUM_SIZE) return;
  const std::size_t body = packet.size() - CHECKSUM_SIZE;
  store_le(packet, body, crc32(packet.first(body)));
}

std::array<std::uint8_t, POSE_PACKET_SIZE> encode_pose(const PosePacket& packet) {
  std::array<std::uint8_t, POSE_PACKET_SIZE> bytes{};
  store_header(bytes, PacketType::pose, packet.sequence, packet.send_time_s);
  for (std::size_t i = 0; i < 3; ++i) store_f64(bytes, OFFSET_POSITION + 8 * i, packet.pose.position_m[i]);
  for (std::size_t i = 0; i < 4; ++i) store_f64(bytes, OFFSET_ORIENTATION + 8 * i, packet.pose.orientation_wxyz[i]);
  store_le(bytes, OFFSET_TOOL_MODE, static_cast<std::uint32_t>(packet.pose.mode));
  store_le(bytes, OFFSET_POSE_RESERVED, std::uint32_t{0});
  write_checksum(bytes);
  return bytes;
}

std::array<std::uint8_t, FORCE_PACKET_SIZE> encode_force(const ForcePacket& packet) {
  std::array<std::uint8_t, FORCE_PACKET_SIZE> bytes{};
  store_header(bytes, PacketType::force, packet.sequence, packet.send_time_s);
  for (std::size_t i = 0; i < 3; ++i) store_f64(bytes, OFFSET_FORCE + 8 * i, packet.force_n[i]);
  store_f64(bytes, OFFSET_SCALE, packet.watchdog_scale);
  store_le(bytes, OFFSET_ACK, packet.ack_sequence);
  write_checksum(bytes);
  return bytes;
}

DecodeError decode_pose(std::span<const std::uint8_t> datagram, PosePacket& out) {
  if (const DecodeError e = check_header(datagram, PacketType::pose, POSE_PACKET_SIZE); e != DecodeError::none) {
    return e;
  }
  if (load_le<std::uint32_t>(datagram, OFFSET_POSE_RESERVED) != 0) return DecodeError::nonzero_reserved;
  PosePacket p;
  p.sequence = load_le<std::uint64_t>(datagram, OFFSET_SEQUENCE);
  p.send_time_s = load_f64(datagram, OFFSET_SEND_TIME);
  double norm_squared = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    p.pose.position_m[i] = load_f64(datagram, OFFSET_POSITION + 8 * i);
    if (!std::isfinite(p.pose.position_m[i])) return DecodeError::non_finite;
  }
  for (std::size_t i = 0; i < 4; ++i) {
    const double q = load_f64(datagram, OFFSET_ORIENTATION + 8 * i);
    if (!std::isfinite(q)) return DecodeError::non_finite;
    p.pose.orientation_wxyz[i] = q;
    norm_squared += q * q;
  }
  // A finite quaternion can still overflow its squared norm (components near 1e200).
  if (!std::isfinite(norm_squared)) return DecodeError::non_finite;
  if (norm_squared < MIN_QUATERNION_NORM_SQUARED) return DecodeError::zero_quaternion;
  const std::uint32_t mode = load_le<std::uint32_t>(datagram, OFFSET_TOOL_MODE);
  const std::optional<ToolMode> known = tool_mode_of(mode);
  if (!known) return DecodeError::unknown_tool_mode;
  p.pose.mode = *known;
  out = p;
  return DecodeError::none;
}

DecodeError decode_force(std::span<const std::uint8_t> datagram, ForcePacket& out) {
  if (const DecodeError e = check_header(datagram, PacketType::force, FORCE_PACKET_SIZE); e != DecodeError::none) {
    return e;
  }
  ForcePacket p;
  p.sequence = load_le<std::uint64_t>(datagram, OFFSET_SEQUENCE);
  p.send_time_s = load_f64(datagram, OFFSET_SEND_TIME);
  for (std::size_t i = 0; i < 3; ++i) {
    p.force_n[i] = load_f64(datagram, OFFSET_FORCE + 8 * i);
    if (!std::isfinite(p.force_n[i])) return DecodeError::non_finite;
  }
  p.watchdog_scale = load_f64(datagram, OFFSET_SCALE);
  if (!std::isfinite(p.watchdog_scale)) return DecodeError::non_finite;
  if (p.watchdog_scale < 0.0 || p.watchdog_scale > 1.0) return DecodeError::scale_out_of_range;
  p.ack_sequence = load_le<std::uint64_t>(datagram, OFFSET_ACK);
  out = p;
  return DecodeError::none;
}

}  // namespace tissue::host::udp
