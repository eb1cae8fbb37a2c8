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
inline constexpr std::uint32_t VIEW_FRAME_TRIANGLES = 1;  ///< flag: the triangles (and a mapped frame's embedding) follow
inline constexpr std::uint32_t VIEW_FRAME_MAPPED = 2;     ///< flag: the positions are nodes the page maps the points from

/// What the frame shows beyond the surface: the force on the hand and the device's limit.
struct ViewOverlay {
  std::array<double, 3> device_force_n{};
  double device_max_force_n = 0.0;
  std::uint32_t topology_revision = 0;  ///< changes when the triangles change
};

/// One frame in both forms: `plain` without the triangles, `with_triangles` the same bytes with the
/// flag set and the triangles appended (both replaced; their capacity is kept). A frame with an
/// embedding is sent mapped: the positions are its coarse nodes, and the embedding travels with the
/// triangles (once per topology revision), so the page maps the fine surface itself. Checks `frame`
/// first (validate_surface_frame(): throws OutputError for an inconsistent one).
void encode_view_frames(const SurfaceFrame& frame, const ViewOverlay& overlay, std::string& plain,
                        std::string& with_triangles);

}  // namespace tissue::host
