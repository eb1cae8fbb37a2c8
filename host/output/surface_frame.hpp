// surface_frame.hpp - one frame of the tissue's deformed surface as the host reads it from the
// Tissue FMU (surface.vertexPositions, surface.triangles, contact.*, tool.*), plus what the
// writers of host/output/ share: the frame check they apply before using a frame, and the file
// write that replaces a file whole (so that ParaView never reads half a frame).
#pragma once

#include "ports/surface_binary.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace tissue::host {

/// Refusal of invalid input or a failed write in host/output/ (what and where in the message).
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/**
 * The deformed surface at one instant, as plain arrays.
 *
 * positions_m: 3 * vertex_count values (x y z per vertex, metres). triangles: 3 * triangle_count
 * 0-based vertex indices, counter-clockwise seen from outside. The first mesh_triangle_count
 * triangles are the mesh's own surface; the rest are cut faces. Vertices no triangle references
 * (the FMU outputs interior mesh vertices too) are allowed.
 */
struct SurfaceFrame {
  double time_s = 0;
  std::vector<double> positions_m;
  std::vector<std::uint32_t> triangles;
  std::size_t mesh_triangle_count = 0;
  /// The surface as a map of coarse nodes (the Tissue FMU's surface.embedding and surface.nodes), for
  /// a viewer that maps on its side: the embedding (shared, replaced when a cut changes it) and the
  /// nodes' positions; positions_m and triangles are then the mapped points and the embedding's
  /// triangles. Null: the frame has positions only.
  std::shared_ptr<const ports::SurfaceEmbedding> embedding;
  std::vector<double> node_positions_m;
  /// A frame captured without its mapping (TissueLink::read_surface_unmapped, the recording's in the
  /// dynamics thread's slot): the embedding's encoded bytes (shared while the surface's revision
  /// stands) and the nodes' revision; positions_m, triangles and embedding are filled later, in the
  /// writer's thread (SurfaceMapping::complete). Null: the frame is complete.
  std::shared_ptr<const std::vector<std::uint8_t>> embedding_bytes;
  std::uint64_t node_revision = 0;
  // Optional overlays.
  bool has_tool = false;
  std::array<double, 3> tool_tip_m{}, tool_handle_m{};
  int tool_mode = 0;  ///< the FMU's tool.mode: 0 none, 1 probe, 2 scalpel (device.hpp's ToolMode)
  bool contact_active = false;
  std::array<double, 3> contact_point_m{}, force_n{};

  [[nodiscard]] std::size_t vertex_count() const { return positions_m.size() / 3; }
  [[nodiscard]] std::size_t triangle_count() const { return triangles.size() / 3; }
};

namespace detail {
inline bool all_finite(const double* values, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}
}  // namespace detail

/**
 * Throws OutputError unless @p frame is consistent: time finite; positions_m and triangles of a
 * length divisible by 3; every position finite; every index < vertex_count();
 * mesh_triangle_count <= triangle_count(); tool_mode in 0..2; the tool's points finite when
 * has_tool; contact point and force finite when contact_active. @p where prefixes the message.
 */
inline void validate_surface_frame(const SurfaceFrame& frame, const std::string& where) {
  const auto fail = [&where](const std::string& what) { throw OutputError(where + ": " + what); };
  if (!std::isfinite(frame.time_s)) fail("time_s is not finite");
  if (frame.positions_m.size() % 3 != 0) {
    fail("positions_m has " + std::to_string(frame.positions_m.size()) + " values, not a multiple of 3");
  }
  if (frame.triangles.size() % 3 != 0) {
    fail("triangles has " + std::to_string(frame.triangles.size()) + " indices, not a multiple of 3");
  }
  for (std::size_t i = 0; i < frame.positions_m.size(); ++i) {
    if (!std::isfinite(frame.positions_m[i])) {
      fail("vertex " + std::to_string(i / 3) + " has a non-finite coordinate " + std::to_string(i % 3));
    }
  }
  const std::size_t vertex_count = frame.vertex_count();
  for (std::size_t i = 0; i < frame.triangles.size(); ++i) {
    if (frame.triangles[i] >= vertex_count) {
      fail("triangle " + std::to_string(i / 3) + " references vertex " + std::to_string(frame.triangles[i]) + " of " +
           std::to_string(vertex_count));
    }
  }
  if (frame.embedding != nullptr) {
    if (frame.node_positions_m.size() != 3 * frame.embedding->node_count ||
        frame.embedding->point_count() != vertex_count || frame.embedding->triangles != frame.triangles) {
      fail("the nodes, points or triangles are not those of the embedding");
    }
    if (!detail::all_finite(frame.node_positions_m.data(), frame.node_positions_m.size())) {
      fail("a node has a non-finite coordinate");
    }
  }
  if (frame.mesh_triangle_count > frame.triangle_count()) {
    fail("mesh_triangle_count " + std::to_string(frame.mesh_triangle_count) + " exceeds the " +
         std::to_string(frame.triangle_count()) + " triangles");
  }
  if (frame.tool_mode < 0 || frame.tool_mode > 2) fail("tool_mode " + std::to_string(frame.tool_mode) + " is not 0..2");
  if (frame.has_tool &&
      !(detail::all_finite(frame.tool_tip_m.data(), 3) && detail::all_finite(frame.tool_handle_m.data(), 3))) {
    fail("the tool's tip or handle is not finite");
  }
  if (frame.contact_active &&
      !(detail::all_finite(frame.contact_point_m.data(), 3) && detail::all_finite(frame.force_n.data(), 3))) {
    fail("the contact point or force is not finite");
  }
}

/**
 * Writes @p bytes to @p path through a sibling temporary file renamed over @p path, so that a
 * reader sees either the old file or the whole new one. Throws OutputError naming the path.
 */
inline void write_output_file(const std::filesystem::path& path, std::string_view bytes) {
  std::filesystem::path temporary = path;
  temporary += ".partial";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw OutputError("cannot open " + temporary.string() + " for writing");
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      std::error_code ignored;
      std::filesystem::remove(temporary, ignored);
      throw OutputError("cannot write " + temporary.string());
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw OutputError("cannot rename " + temporary.string() + " to " + path.string() + ": " + error.message());
  }
}

}  // namespace tissue::host
