// view_frame.cpp - see view_frame.hpp and VIEW_PROTOCOL.md for the layout.
#include "view/view_frame.hpp"

#include <bit>
#include <cstring>

namespace tissue::host {
namespace {

static_assert(std::endian::native == std::endian::little, "the view frame is written as little-endian memory");

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

void put_vector(std::string& out, const std::array<double, 3>& v) {
  for (const double x : v) put(out, static_cast<float>(x));
}

// The header and the positions (the nodes, for a mapped frame), with the triangles flag clear.
void encode_plain(const SurfaceFrame& frame, const ViewOverlay& overlay, std::string& out) {
  validate_surface_frame(frame, "view frame");
  const bool mapped = frame.embedding != nullptr;
  const std::vector<double>& positions_m = mapped ? frame.node_positions_m : frame.positions_m;
  out.clear();
  put(out, VIEW_FRAME_MAGIC);
  put(out, mapped ? VIEW_FRAME_MAPPED : std::uint32_t{0});  // flags: no triangles
  put(out, static_cast<std::uint32_t>(positions_m.size() / 3));
  put(out, static_cast<std::uint32_t>(frame.triangle_count()));
  put(out, static_cast<std::uint32_t>(frame.mesh_triangle_count));
  put(out, overlay.topology_revision);
  put(out, frame.time_s);
  // The tool is shown where it is even when put away (mode none), if its points are finite.
  const bool tool_finite = detail::all_finite(frame.tool_tip_m.data(), 3) && detail::all_finite(frame.tool_handle_m.data(), 3);
  put_vector(out, tool_finite ? frame.tool_tip_m : std::array<double, 3>{});
  put_vector(out, tool_finite ? frame.tool_handle_m : std::array<double, 3>{});
  put(out, static_cast<std::uint32_t>(frame.has_tool ? frame.tool_mode : 0));
  put(out, static_cast<std::uint32_t>(frame.contact_active ? 1 : 0));
  put_vector(out, frame.contact_point_m);
  put_vector(out, overlay.device_force_n);
  put(out, static_cast<float>(overlay.device_max_force_n));
  put(out, static_cast<std::uint32_t>(mapped ? frame.vertex_count() : 0));  // the points P of a mapped frame
  for (const double x : positions_m) put(out, static_cast<float>(x));
}

}  // namespace

void encode_view_frames(const SurfaceFrame& frame, const ViewOverlay& overlay, std::string& plain,
                        std::string& with_triangles) {
  encode_plain(frame, overlay, plain);
  with_triangles = plain;
  const std::uint32_t flags = VIEW_FRAME_TRIANGLES | (frame.embedding != nullptr ? VIEW_FRAME_MAPPED : 0U);
  std::memcpy(with_triangles.data() + 4, &flags, sizeof(flags));
  if (frame.embedding != nullptr) {  // the embedding travels with the triangles
    for (const std::uint32_t node : frame.embedding->point_nodes) put(with_triangles, node);
    for (const double weight : frame.embedding->point_weights) put(with_triangles, static_cast<float>(weight));
  }
  for (const std::uint32_t index : frame.triangles) put(with_triangles, index);
}

}  // namespace tissue::host
