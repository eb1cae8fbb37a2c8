// Codec (see igtl_codec.hpp): the OpenIGTLink library's message classes behind our pose, force and surface.
#include "igtl/igtl_codec.hpp"

#include <igtlMessageHeader.h>
#include <igtlPolyDataMessage.h>
#include <igtlSensorMessage.h>
#include <igtlTimeStamp.h>
#include <igtlTransformMessage.h>
#include <igtlUnit.h>
#include <igtl_position.h>
#include <igtl_transform.h>
#include <igtl_unit.h>
#include <igtl_util.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <limits>

namespace tissue::host::igtl_link {
namespace {

std::uint64_t big_endian(const std::uint8_t* bytes, std::size_t count) {
  std::uint64_t value = 0;
  for (std::size_t i = 0; i < count; ++i) value = (value << 8U) | bytes[i];
  return value;
}

std::string fixed_text(const std::uint8_t* bytes, std::size_t count) {
  std::size_t length = 0;
  while (length < count && bytes[length] != 0) ++length;
  return {reinterpret_cast<const char*>(bytes), length};
}

// A rotation up to the float32 precision of the wire and a tracker's noise: R^T R = I and det R = 1
// within 1e-3 (a scaled or sheared matrix is refused, not silently made a rotation).
constexpr double ROTATION_TOLERANCE = 1e-3;

float big_endian_float(const std::uint8_t* bytes) {
  const auto bits = static_cast<std::uint32_t>(big_endian(bytes, 4));
  float value = 0.0F;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

bool finite(const float* values, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

void append_packed(igtl::MessageBase& message, std::vector<std::uint8_t>& out) {
  message.Pack();
  const auto* bytes = static_cast<const std::uint8_t*>(message.GetPackPointer());
  out.insert(out.end(), bytes, bytes + message.GetPackSize());
}

}  // namespace

Header read_header(std::span<const std::uint8_t, HEADER_SIZE> bytes) {
  Header header;
  header.version = static_cast<std::uint16_t>(big_endian(bytes.data(), 2));
  header.type = fixed_text(bytes.data() + 2, 12);
  header.device_name = fixed_text(bytes.data() + 14, 20);
  header.timestamp = big_endian(bytes.data() + 34, 8);
  header.body_size = big_endian(bytes.data() + 42, 8);
  return header;
}

struct Codec::Messages {
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  igtl::TransformMessage::Pointer transform = igtl::TransformMessage::New();
  igtl::SensorMessage::Pointer sensor = igtl::SensorMessage::New();
  igtl::TimeStamp::Pointer now = igtl::TimeStamp::New();
};

Codec::Codec(CodecSettings settings) : m_settings(std::move(settings)), m_messages(std::make_unique<Messages>()) {
  if (!(std::isfinite(m_settings.length_unit_m) && m_settings.length_unit_m > 0.0)) {
    throw std::invalid_argument("OpenIGTLink length unit must be finite and > 0 m, got " +
                                std::to_string(m_settings.length_unit_m));
  }
  for (const std::string* name :
       {&m_settings.probe_transform, &m_settings.scalpel_transform, &m_settings.force_name, &m_settings.surface_name}) {
    if (name->empty() || name->size() > 20) {
      throw std::invalid_argument("OpenIGTLink device name '" + *name + "' must have 1 to 20 characters");
    }
  }
  if (m_settings.probe_transform == m_settings.scalpel_transform) {
    throw std::invalid_argument("OpenIGTLink: the probe and the scalpel need different transform names, both are '" +
                                m_settings.probe_transform + "'");
  }
  igtl::Unit::Pointer newton = igtl::Unit::New();
  newton->Init();
  newton->Append(IGTL_UNIT_SI_DERIVED_NEWTON, 1);
  Messages& m = *m_messages;
  m.sensor->SetDeviceName(m_settings.force_name.c_str());
  m.sensor->SetLength(3);
  m.sensor->SetUnit(newton);
}

Codec::~Codec() = default;

Verdict Codec::decode_pose(std::span<const std::uint8_t> message, DevicePose& pose) {
  if (message.size() < HEADER_SIZE) return Verdict::malformed;
  return decode_pose(read_header(message.first<HEADER_SIZE>()), message, pose);
}

Verdict Codec::decode_pose(const Header& header, std::span<const std::uint8_t> message, DevicePose& pose) {
  if (message.size() < HEADER_SIZE) return Verdict::malformed;
  const std::size_t body_size = message.size() - HEADER_SIZE;
  if (header.body_size != body_size) return Verdict::malformed;
  const bool transform = header.type == "TRANSFORM";
  const bool position = header.type == "POSITION";
  if (!transform && !position) return Verdict::ignored;
  ToolMode mode = ToolMode::none;
  if (header.device_name == m_settings.probe_transform) {
    mode = ToolMode::probe;
  } else if (header.device_name == m_settings.scalpel_transform) {
    mode = ToolMode::scalpel;
  } else {
    return Verdict::ignored;
  }
  if (header.version != 1) return Verdict::malformed;  // version 2 adds an extended header we do not read

  Eigen::Vector3d position_units;
  Eigen::Quaterniond orientation;
  if (transform) {
    if (body_size != IGTL_TRANSFORM_SIZE) return Verdict::malformed;
    Messages& m = *m_messages;
    m.header->InitPack();
    std::memcpy(m.header->GetPackPointer(), message.data(), HEADER_SIZE);
    m.header->Unpack();
    m.transform->SetMessageHeader(m.header);
    m.transform->AllocatePack();
    if (static_cast<std::size_t>(m.transform->GetPackBodySize()) != body_size) return Verdict::malformed;
    std::memcpy(m.transform->GetPackBodyPointer(), message.data() + HEADER_SIZE, body_size);
    if ((m.transform->Unpack(1) & igtl::MessageBase::UNPACK_BODY) == 0) return Verdict::malformed;  // CRC
    igtl::Matrix4x4 matrix;
    m.transform->GetMatrix(matrix);
    if (!finite(&matrix[0][0], 16)) return Verdict::malformed;
    Eigen::Matrix3d rotation;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) rotation(r, c) = matrix[r][c];
      position_units[r] = matrix[r][3];
    }
    const double off_identity = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (off_identity > ROTATION_TOLERANCE || std::abs(rotation.determinant() - 1.0) > ROTATION_TOLERANCE) {
      return Verdict::malformed;
    }
    orientation = Eigen::Quaterniond(rotation);
  } else {
    // Read here, not by the library: libopenigtlink 1.11 converts the byte order of all 28 bytes
    // even for the 12- and 24-byte forms, past the end of the body.
    if (body_size != IGTL_POSITION_MESSAGE_POSITON_ONLY_SIZE &&
        body_size != IGTL_POSITION_MESSAGE_WITH_QUATERNION3_SIZE && body_size != IGTL_POSITION_MESSAGE_DEFAULT_SIZE) {
      return Verdict::malformed;
    }
    const std::uint8_t* body = message.data() + HEADER_SIZE;
    std::vector<std::uint8_t> body_copy(body, body + body_size);  // crc64 takes a mutable pointer
    if (crc64(body_copy.data(), body_size, 0) != big_endian(message.data() + 50, 8)) return Verdict::malformed;
    std::array<float, 3> p{};
    std::array<float, 4> q{0.0F, 0.0F, 0.0F, 1.0F};  // x y z w
    for (std::size_t i = 0; i < 3; ++i) p[i] = big_endian_float(body + 4 * i);
    if (body_size >= IGTL_POSITION_MESSAGE_WITH_QUATERNION3_SIZE) {
      for (std::size_t i = 0; i < 3; ++i) q[i] = big_endian_float(body + 12 + 4 * i);
      if (body_size == IGTL_POSITION_MESSAGE_DEFAULT_SIZE) {
        q[3] = big_endian_float(body + 24);
      } else {  // the unit quaternion's w >= 0 from its vector part
        const double w2 = 1.0 - (double{q[0]} * q[0] + double{q[1]} * q[1] + double{q[2]} * q[2]);
        if (!(w2 >= -1e-6)) return Verdict::malformed;
        q[3] = static_cast<float>(std::sqrt(std::max(0.0, w2)));
      }
    }
    if (!finite(p.data(), 3) || !finite(q.data(), 4)) return Verdict::malformed;
    position_units = {p[0], p[1], p[2]};
    orientation = Eigen::Quaterniond(q[3], q[0], q[1], q[2]);
    if (!(orientation.norm() > 0.5 && orientation.norm() < 2.0)) return Verdict::malformed;
  }
  orientation.normalize();
  const Eigen::Vector3d position_m = position_units * m_settings.length_unit_m;
  if (!position_m.allFinite()) return Verdict::malformed;
  for (int a = 0; a < 3; ++a) pose.position_m[static_cast<std::size_t>(a)] = position_m[a];
  pose.orientation_wxyz = {orientation.w(), orientation.x(), orientation.y(), orientation.z()};
  pose.mode = mode;
  return Verdict::pose;
}

void Codec::append_force(const std::array<double, 3>& force_n, std::vector<std::uint8_t>& out) {
  Messages& m = *m_messages;
  for (unsigned i = 0; i < 3; ++i) m.sensor->SetValue(i, force_n[i]);
  m.now->GetTime();
  m.sensor->SetTimeStamp(m.now);
  append_packed(*m.sensor, out);
}

void Codec::append_surface(const SurfaceFrame& frame, std::vector<std::uint8_t>& out) {
  // Only the points the triangles use (the frame carries interior vertices too), renumbered.
  constexpr std::uint32_t UNUSED = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> renumbered(frame.vertex_count(), UNUSED);
  igtl::PolyDataPointArray::Pointer points = igtl::PolyDataPointArray::New();
  igtl::PolyDataCellArray::Pointer polygons = igtl::PolyDataCellArray::New();
  const double scale = 1.0 / m_settings.length_unit_m;
  std::array<igtlUint32, 3> cell{};
  for (std::size_t t = 0; t < frame.triangle_count(); ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = frame.triangles[3 * t + k];
      if (renumbered[v] == UNUSED) {
        renumbered[v] = static_cast<std::uint32_t>(points->GetNumberOfPoints());
        points->AddPoint(static_cast<igtlFloat32>(frame.positions_m[3 * v] * scale),
                         static_cast<igtlFloat32>(frame.positions_m[3 * v + 1] * scale),
                         static_cast<igtlFloat32>(frame.positions_m[3 * v + 2] * scale));
      }
      cell[k] = renumbered[v];
    }
    polygons->AddCell(3, cell.data());
  }
  igtl::PolyDataMessage::Pointer message = igtl::PolyDataMessage::New();
  message->SetDeviceName(m_settings.surface_name.c_str());
  message->SetPoints(points);
  message->SetPolygons(polygons);
  Messages& m = *m_messages;
  m.now->GetTime();
  message->SetTimeStamp(m.now);
  append_packed(*message, out);
}

}  // namespace tissue::host::igtl_link
