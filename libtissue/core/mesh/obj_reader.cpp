// Wavefront .obj render surfaces: closed, consistently oriented triangle meshes (mesh_io.hpp).
#include "core/mesh/mesh_io.hpp"

#include "core/mesh/mesh_io_detail.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace tissue {

using namespace mesh_io_detail;  // NOLINT(google-build-using-namespace): the readers' own helpers

namespace {

// The surface of a solid: every edge run by exactly two triangles, once each way.
void check_closed_manifold(const TriangleSurface& surface, const std::string& source,
                           const std::vector<int>& triangle_lines) {
  std::map<std::pair<int, int>, std::pair<int, int>> runs;  // edge (lower first) -> runs a->b, b->a
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    for (size_t k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      auto& [forward, backward] = runs[{std::min(a, b), std::max(a, b)}];
      (a < b ? forward : backward) += 1;
      const std::string edge =
          "triangle " + std::to_string(t + 1) + ": edge " + std::to_string(a + 1) + "-" + std::to_string(b + 1);
      if (forward + backward > 2) {
        fail(source, triangle_lines[t], static_cast<int>(t + 1),
             edge + " is shared by more than two triangles (not manifold)");
      }
      if (forward > 1 || backward > 1) {
        fail(source, triangle_lines[t], static_cast<int>(t + 1),
             edge + " is run the same way by two triangles (not consistently oriented)");
      }
    }
  }
  for (const auto& [edge, counts] : runs) {
    if (counts.first + counts.second != 2) {
      fail(source, 0, 0,
           "edge " + std::to_string(edge.first + 1) + "-" + std::to_string(edge.second + 1) +
               " borders a single triangle (the surface is not closed)");
    }
  }
}

}  // namespace

TriangleSurface parse_obj(std::string_view text, const std::string& source_name) {
  TriangleSurface surface;
  surface.source_name = source_name;
  std::vector<int> triangle_lines;
  LineReader reader(text, '#', false);
  while (reader.next()) {
    const int line = reader.line();
    if (reader[0] == "v") {
      const std::string vertex = "vertex " + std::to_string(surface.vertices_m.size() + 1);
      if (reader.size() < 4) fail(source_name, line, 0, vertex + ": fewer than 3 coordinates");
      Eigen::Vector3d p;
      for (std::size_t a = 0; a < 3; ++a) {
        const std::optional<double> value = parse_double(reader[a + 1]);
        if (!value || !std::isfinite(*value)) {
          fail(source_name, line, 0,
               vertex + ": coordinate '" + std::string(reader[a + 1]) + "' is not a finite number");
        }
        p(static_cast<Eigen::Index>(a)) = *value;
      }
      surface.vertices_m.push_back(p);
    } else if (reader[0] == "f") {
      const int face = static_cast<int>(triangle_lines.size()) + 1;
      if (reader.size() < 4) fail(source_name, line, 0, "face with fewer than 3 corners");
      std::vector<int> corners;
      const auto count = static_cast<std::int64_t>(surface.vertices_m.size());
      for (std::size_t k = 1; k < reader.size(); ++k) {
        const std::optional<std::int64_t> index = parse_int(reader[k].substr(0, reader[k].find('/')));
        const std::int64_t resolved = index && *index < 0 ? count + *index : (index ? *index - 1 : -1);
        if (!index || *index == 0 || resolved < 0 || resolved >= count) {
          fail(source_name, line, 0,
               "face corner '" + std::string(reader[k]) + "' is not a vertex (" + std::to_string(count) +
                   " read so far)");
        }
        corners.push_back(static_cast<int>(resolved));
      }
      for (size_t a = 0; a < corners.size(); ++a) {
        for (size_t b = a + 1; b < corners.size(); ++b) {
          if (corners[a] == corners[b]) {
            fail(source_name, line, 0,
                 "face " + std::to_string(face) + " repeats vertex " + std::to_string(corners[a] + 1));
          }
        }
      }
      for (size_t k = 1; k + 1 < corners.size(); ++k) {
        surface.triangles.push_back({corners[0], corners[k], corners[k + 1]});
        triangle_lines.push_back(line);
      }
    }
  }
  if (surface.triangles.empty()) fail(source_name, 0, 0, "no triangle (no 'f' record)");
  check_closed_manifold(surface, source_name, triangle_lines);
  return surface;
}

TriangleSurface read_obj(const std::filesystem::path& path) { return parse_obj(read_text(path), path.string()); }

}  // namespace tissue
