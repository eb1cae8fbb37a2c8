// igtl_codec.hpp - the OpenIGTLink messages tissue-host reads and writes (OPENIGTLINK.md), packed
// and unpacked by the OpenIGTLink library (Debian's libopenigtlink): the hand's pose from a
// TRANSFORM or POSITION message, the device force as a SENSOR message, the deformed surface as
// POLYDATA. Lengths on the wire are in the protocol's length unit (millimetres for 3D Slicer and
// PLUS), converted here from and to metres.
#pragma once

#include "device/device.hpp"
#include "output/surface_frame.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace tissue::host::igtl_link {

/// Bytes of an OpenIGTLink header (protocol versions 1 and 2 share it).
inline constexpr std::size_t HEADER_SIZE = 58;

/// A header's fields, read byte by byte (so that the body size is checked before any buffer is sized).
struct Header {
  std::uint16_t version = 0;
  std::string type;             ///< e.g. "TRANSFORM"
  std::string device_name;      ///< e.g. "ProbeToTissue"
  std::uint64_t timestamp = 0;  ///< seconds << 32 | fraction (0: none)
  std::uint64_t body_size = 0;
};
[[nodiscard]] Header read_header(std::span<const std::uint8_t, HEADER_SIZE> bytes);

struct CodecSettings {
  double length_unit_m = 1e-3;                        ///< metres per protocol length unit
  std::string probe_transform = "ProbeToTissue";      ///< the pose of the probe
  std::string scalpel_transform = "ScalpelToTissue";  ///< the pose of the scalpel
  std::string force_name = "TissueForce";             ///< SENSOR message with the device force
  std::string surface_name = "TissueSurface";         ///< POLYDATA message with the surface
};

/// What a received message was.
enum class Verdict {
  pose,       ///< a TRANSFORM or POSITION message of the probe or the scalpel, valid
  ignored,    ///< another type (STATUS, STRING, GET_*, ...) or another device name
  malformed,  ///< a pose message that fails its CRC, has a wrong body size, a non-finite value,
              ///< a matrix that is not a rotation or a zero quaternion; or a header version other than 1
};

class Codec {
 public:
  explicit Codec(CodecSettings settings);
  ~Codec();
  Codec(const Codec&) = delete;
  Codec& operator=(const Codec&) = delete;

  /// Decodes one whole message (header then body). On Verdict::pose, @p pose holds the tool's
  /// position [m], orientation (unit quaternion) and mode (probe or scalpel, by device name).
  Verdict decode_pose(std::span<const std::uint8_t> message, DevicePose& pose);
  /// The same for a message whose header the caller has read already (the server, which reads
  /// it to find where the message ends).
  Verdict decode_pose(const Header& header, std::span<const std::uint8_t> message, DevicePose& pose);
  /// Appends a SENSOR message: 3 values, the force [N] in the scene frame, unit newton.
  void append_force(const std::array<double, 3>& force_n, std::vector<std::uint8_t>& out);
  /// Appends a POLYDATA message of @p frame's triangles, cut faces included (only the points they
  /// use, in the protocol's length unit). No attributes: libopenigtlink 1.11 packs a cell
  /// attribute by reading past its buffer.
  void append_surface(const SurfaceFrame& frame, std::vector<std::uint8_t>& out);

  [[nodiscard]] const CodecSettings& settings() const { return m_settings; }

 private:
  struct Messages;  // the library's message objects, reused
  CodecSettings m_settings;
  std::unique_ptr<Messages> m_messages;
};

}  // namespace tissue::host::igtl_link
