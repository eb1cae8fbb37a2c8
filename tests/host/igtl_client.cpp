// IgtlClient (see igtl_client.hpp).
#include "igtl_client.hpp"

#include <igtlMessageHeader.h>
#include <igtlPolyDataMessage.h>
#include <igtlPositionMessage.h>
#include <igtlSensorMessage.h>
#include <igtlTransformMessage.h>
#include <igtlUnit.h>
#include <igtl_unit.h>
#include <igtl_util.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <list>
#include <stdexcept>

namespace tissue::host::test {

double steady_time_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The connection is plain POSIX (the library's socket class 1.11 passes getsockopt an
// uninitialized length in SetReceiveTimeout); the messages are the library's.
struct IgtlClient::Socket {
  int fd = -1;
  std::mutex send_mutex;
  ~Socket() {
    if (fd >= 0) ::close(fd);
  }
  // Waits up to timeout_ms for data; true if some is there (or the peer closed).
  [[nodiscard]] bool readable(int timeout_ms) const {
    pollfd p{fd, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) > 0;
  }
  // Reads exactly size bytes; false if the connection ended first.
  bool read_fully(void* data, std::size_t size) const {
    auto* bytes = static_cast<std::uint8_t*>(data);
    std::size_t done = 0;
    while (done < size) {
      const ssize_t got = ::recv(fd, bytes + done, size - done, 0);
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return false;
      done += static_cast<std::size_t>(got);
    }
    return true;
  }
};

namespace {

// Rotation matrix of a unit quaternion (w, x, y, z).
void rotation(const std::array<double, 4>& q, igtl::Matrix4x4& m) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  m[0][0] = static_cast<float>(1 - 2 * (y * y + z * z));
  m[0][1] = static_cast<float>(2 * (x * y - w * z));
  m[0][2] = static_cast<float>(2 * (x * z + w * y));
  m[1][0] = static_cast<float>(2 * (x * y + w * z));
  m[1][1] = static_cast<float>(1 - 2 * (x * x + z * z));
  m[1][2] = static_cast<float>(2 * (y * z - w * x));
  m[2][0] = static_cast<float>(2 * (x * z - w * y));
  m[2][1] = static_cast<float>(2 * (y * z + w * x));
  m[2][2] = static_cast<float>(1 - 2 * (x * x + y * y));
  m[3][0] = m[3][1] = m[3][2] = 0.0F;
  m[3][3] = 1.0F;
}

void stamp(igtl::MessageBase& message, std::uint64_t timestamp) {
  if (timestamp == 0) {
    igtl::TimeStamp::Pointer now = igtl::TimeStamp::New();
    now->GetTime();
    message.SetTimeStamp(now);
  } else {
    message.SetTimeStamp(static_cast<unsigned>(timestamp >> 32U), static_cast<unsigned>(timestamp & 0xFFFFFFFFU));
  }
}

}  // namespace

IgtlClient::IgtlClient(const std::string& host, int port, double connect_timeout_s)
    : m_socket(std::make_unique<Socket>()) {
  const double give_up = steady_time_s() + connect_timeout_s;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  if (inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1) {
    throw std::runtime_error("IgtlClient: '" + host + "' is not a numeric IPv4 address");
  }
  while (true) {
    m_socket->fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (::connect(m_socket->fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0) break;
    ::close(m_socket->fd);
    m_socket->fd = -1;
    if (steady_time_s() > give_up) {
      throw std::runtime_error("IgtlClient: cannot connect to " + host + ":" + std::to_string(port));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const int yes = 1;
  ::setsockopt(m_socket->fd, IPPROTO_TCP, TCP_NODELAY, &yes, sizeof(yes));
  m_receiver = std::thread([this] { receive_loop(); });
}

IgtlClient::~IgtlClient() {
  m_stop.store(true);
  m_receiver.join();
}

std::vector<std::uint8_t> pack_transform(const std::string& name, const DevicePose& pose, double length_unit_m,
                                         std::uint64_t timestamp) {
  igtl::TransformMessage::Pointer message = igtl::TransformMessage::New();
  message->SetDeviceName(name.c_str());
  igtl::Matrix4x4 matrix;
  rotation(pose.orientation_wxyz, matrix);
  for (int a = 0; a < 3; ++a)
    matrix[a][3] = static_cast<float>(pose.position_m[static_cast<std::size_t>(a)] / length_unit_m);
  message->SetMatrix(matrix);
  stamp(*message, timestamp);
  message->Pack();
  const auto* bytes = static_cast<const std::uint8_t*>(message->GetPackPointer());
  return {bytes, bytes + message->GetPackSize()};
}

void IgtlClient::send_transform(const std::string& name, const DevicePose& pose, double length_unit_m,
                                std::uint64_t timestamp) {
  send_raw(pack_transform(name, pose, length_unit_m, timestamp));
}

void IgtlClient::send_position(const std::string& name, const DevicePose& pose, double length_unit_m,
                               std::uint64_t timestamp) {
  send_raw(pack_position(name, pose, length_unit_m, timestamp));
}

std::vector<std::uint8_t> pack_position(const std::string& name, const DevicePose& pose, double length_unit_m,
                                        std::uint64_t timestamp, int body_size) {
  igtl::PositionMessage::Pointer message = igtl::PositionMessage::New();
  message->SetDeviceName(name.c_str());
  message->SetPackType(igtl::PositionMessage::ALL);
  message->SetPosition(static_cast<float>(pose.position_m[0] / length_unit_m),
                       static_cast<float>(pose.position_m[1] / length_unit_m),
                       static_cast<float>(pose.position_m[2] / length_unit_m));
  const auto& q = pose.orientation_wxyz;
  message->SetQuaternion(static_cast<float>(q[1]), static_cast<float>(q[2]), static_cast<float>(q[3]),
                         static_cast<float>(q[0]));
  stamp(*message, timestamp);
  message->Pack();
  const auto* bytes = static_cast<const std::uint8_t*>(message->GetPackPointer());
  std::vector<std::uint8_t> packed(bytes, bytes + message->GetPackSize());
  if (body_size == 28) return packed;
  // The 12- and 24-byte forms cut from the full one, with their body size and CRC: the library's
  // own packing of them (1.11) writes past its buffer.
  constexpr std::size_t header_size = 58;
  packed.resize(header_size + static_cast<std::size_t>(body_size));
  const std::uint64_t crc = crc64(packed.data() + header_size, static_cast<igtl_uint64>(body_size), 0);
  for (std::size_t i = 0; i < 8; ++i) {
    packed[42 + i] = static_cast<std::uint8_t>(static_cast<std::uint64_t>(body_size) >> (8U * (7 - i)));
    packed[50 + i] = static_cast<std::uint8_t>(crc >> (8U * (7 - i)));
  }
  return packed;
}

void IgtlClient::send_raw(const std::vector<std::uint8_t>& bytes) {
  const std::lock_guard lock(m_socket->send_mutex);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t sent = ::send(m_socket->fd, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) throw std::runtime_error("IgtlClient: send failed");
    done += static_cast<std::size_t>(sent);
  }
}

std::vector<ReceivedForce> IgtlClient::forces() const {
  const std::lock_guard lock(m_mutex);
  return m_forces;
}

std::optional<ReceivedSurface> IgtlClient::last_surface() const {
  const std::lock_guard lock(m_mutex);
  return m_surface;
}

std::size_t IgtlClient::surface_count() const {
  const std::lock_guard lock(m_mutex);
  return m_surface_count;
}

void IgtlClient::receive_loop() {
  igtl::MessageHeader::Pointer header = igtl::MessageHeader::New();
  const Socket& socket = *m_socket;
  while (!m_stop.load()) {
    if (!socket.readable(100)) continue;  // checks m_stop every 100 ms
    header->InitPack();
    if (!socket.read_fully(header->GetPackPointer(), static_cast<std::size_t>(header->GetPackSize()))) break;
    header->Unpack();
    const std::string type = header->GetDeviceType();
    if (type == "SENSOR") {
      igtl::SensorMessage::Pointer sensor = igtl::SensorMessage::New();
      sensor->SetMessageHeader(header);
      sensor->AllocatePack();
      if (!socket.read_fully(sensor->GetPackBodyPointer(), static_cast<std::size_t>(sensor->GetPackBodySize()))) break;
      if ((sensor->Unpack(1) & igtl::MessageBase::UNPACK_BODY) == 0 || sensor->GetLength() != 3) continue;
      ReceivedForce force;
      force.receive_time_s = steady_time_s();
      for (unsigned i = 0; i < 3; ++i) force.force_n[i] = sensor->GetValue(i);
      igtl::Unit::Pointer unit = igtl::Unit::New();
      sensor->GetUnit(unit);
      igtl::Unit::Pointer newton = igtl::Unit::New();
      newton->Init();
      newton->Append(IGTL_UNIT_SI_DERIVED_NEWTON, 1);
      force.unit_is_newton = unit->Pack() == newton->Pack();
      const std::lock_guard lock(m_mutex);
      m_forces.push_back(force);
    } else if (type == "POLYDATA") {
      igtl::PolyDataMessage::Pointer poly = igtl::PolyDataMessage::New();
      poly->SetMessageHeader(header);
      poly->AllocatePack();
      if (!socket.read_fully(poly->GetPackBodyPointer(), static_cast<std::size_t>(poly->GetPackBodySize()))) break;
      if ((poly->Unpack(1) & igtl::MessageBase::UNPACK_BODY) == 0) continue;
      ReceivedSurface surface;
      surface.name = poly->GetDeviceName();
      igtl::PolyDataPointArray::Pointer points = poly->GetPoints();
      igtl::PolyDataCellArray::Pointer polygons = poly->GetPolygons();
      surface.points = points ? static_cast<std::size_t>(points->GetNumberOfPoints()) : 0;
      surface.polygons = polygons ? polygons->GetNumberOfCells() : 0;
      for (std::size_t i = 0; i < surface.points; ++i) {
        std::array<float, 3> p{};
        points->GetPoint(static_cast<unsigned>(i), p.data());
        surface.point_list.push_back(p);
      }
      for (std::size_t i = 0; i < surface.polygons; ++i) {
        std::list<igtlUint32> cell;
        polygons->GetCell(static_cast<unsigned>(i), cell);
        if (cell.size() != 3) continue;
        auto it = cell.begin();
        const std::uint32_t a = *it++, b = *it++, c = *it;
        surface.triangles.push_back({a, b, c});
      }
      const std::lock_guard lock(m_mutex);
      m_surface = std::move(surface);
      ++m_surface_count;
    } else {
      m_other.fetch_add(1);
      std::vector<std::uint8_t> body(static_cast<std::size_t>(header->GetBodySizeToRead()));
      if (!socket.read_fully(body.data(), body.size())) break;
    }
  }
  m_closed.store(true);
}

}  // namespace tissue::host::test
