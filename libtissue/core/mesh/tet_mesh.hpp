// TetMesh: the rest geometry and connectivity of a tetrahedral mesh, in metres.
// Produced by the readers (mesh_io.hpp); consumed by fem/ and the adjacency/surface tools.
#pragma once

#include "core/material/region_materials.hpp"

#include <Eigen/Core>

#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tissue {

using Tet = std::array<int, 4>;  ///< four 0-based vertex indices, positively oriented

struct TetMesh {
  std::vector<Eigen::Vector3d> rest_positions_m;  ///< one per vertex [m]
  std::vector<Tet> tets;                          ///< positive signed volume after loading
  /// The named regions the file declares (issue 25); empty: the whole mesh is one region.
  std::vector<MeshRegion> regions;
  /// Per tet, its index in `regions`; empty when `regions` is.
  std::vector<int> tet_regions;

  [[nodiscard]] int region_count() const { return regions.empty() ? 1 : static_cast<int>(regions.size()); }
  [[nodiscard]] int region_of(int t) const { return tet_regions.empty() ? 0 : tet_regions[static_cast<size_t>(t)]; }

  [[nodiscard]] int vertex_count() const { return static_cast<int>(rest_positions_m.size()); }
  [[nodiscard]] int tet_count() const { return static_cast<int>(tets.size()); }
  /// The rest positions of tet t's four vertices, in its local order [m].
  [[nodiscard]] std::array<Eigen::Vector3d, 4> rest_corners(int t) const {
    const Tet& tet = tets[static_cast<size_t>(t)];
    return {rest_positions_m[static_cast<size_t>(tet[0])], rest_positions_m[static_cast<size_t>(tet[1])],
            rest_positions_m[static_cast<size_t>(tet[2])], rest_positions_m[static_cast<size_t>(tet[3])]};
  }
};

/// Signed volume of the tet (a, b, c, d): ((b-a) x (c-a)) . (d-a) / 6. Positive = correctly oriented.
double signed_tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& d);

/// A mesh that cannot be used. The message names the file, the line (0 if none) and the
/// element (-1 if none; 0-based index as in TetMesh, the message also gives the file's own numbering).
class MeshError : public std::runtime_error {
 public:
  MeshError(const std::string& message, std::string file, int line, int element)
      : std::runtime_error(message), m_file(std::move(file)), m_line(line), m_element(element) {}
  [[nodiscard]] const std::string& file() const { return m_file; }
  [[nodiscard]] int line() const { return m_line; }
  [[nodiscard]] int element() const { return m_element; }

 private:
  std::string m_file;
  int m_line;
  int m_element;
};

}  // namespace tissue
