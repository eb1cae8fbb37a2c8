// view_frame.hpp - one frame of the live view as the bytes of VIEW_PROTOCOL.md's binary message:
// the surface, the tool, the contact and the device force. A pure function of its inputs.
#pragma once

#include "output/surface_frame.hpp"

#include <array>
#include <cstdint>
#include <string>

namespace tissue::host {

inline constexpr std::uint32_t VIEW_FRAME_MAGIC = 0x31465654;  // "TVF1" read as little-endian bytes
inline constexpr std::size_t VIEW_FRAME_HEADER_BYTES = 96;

/// What the frame shows beyond the surface: the force on the hand and the device's limit.
struct ViewOverlay {
  std::array<double, 3> device_force_n{};
  double device_max_force_n = 0.0;
  std::uint32_t topology_revision = 0;  ///< changes when the triangles change
};

/// Encodes `frame` (validate_surface_frame() first: throws OutputError for an inconsistent one)
/// into `out` (replaced; its capacity is kept), with the triangles when `with_triangles`.
void encode_view_frame(const SurfaceFrame& frame, const ViewOverlay& overlay, bool with_triangles, std::string& out);

}  // namespace tissue::host
