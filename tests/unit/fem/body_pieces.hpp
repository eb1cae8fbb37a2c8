// The bodies a cut body consists of, found from its elements alone (for tests that judge a cut by
// what falls): the rows each uncut tet and each live cut-tet piece use (a real vertex's u or a
// ghost's c) joined into connected components. A component that holds a fixed vertex is held; its
// mass is computed from the geometry (rho V of its uncut tets, rho w_p V of its pieces), not from the
// body's lumped masses, so that a test can compare the two.
#pragma once

#include "core/fem/deformable_body.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

namespace tissue::xfem_test {

struct BodyPiece {
  std::vector<int> rows;  ///< block rows of the unknowns that move it
  bool held = false;      ///< it holds a fixed vertex
  double mass_kg = 0.0;   ///< from the geometry: rho V of its tets and pieces
  double volume_m3 = 0.0;
};

/// The connected pieces of `body`, largest mass first.
inline std::vector<BodyPiece> body_pieces(const DeformableBody& body) {
  const TetMesh& mesh = body.mesh();
  const int rows = body.dof_count() / 3;
  // Union-find over the rows, plus one node for "held" (index rows).
  std::vector<int> parent(static_cast<size_t>(rows + 1));
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int a) {
    while (parent[static_cast<size_t>(a)] != a) a = parent[static_cast<size_t>(a)] = parent[static_cast<size_t>(parent[static_cast<size_t>(a)])];
    return a;
  };
  const auto join = [&](int a, int b) { parent[static_cast<size_t>(find(a))] = find(b); };
  const int held = rows;
  std::vector<double> element_mass;
  std::vector<double> element_volume;
  std::vector<int> element_row;  // a row of each element (or `held`)
  const auto element = [&](const std::array<int, 4>& element_rows, double volume_m3, double density) {
    int first = -1;
    for (const int row : element_rows) {
      const int node = row < 0 ? held : row;
      if (first < 0) first = node;
      join(node, first);
    }
    element_mass.push_back(density * volume_m3);
    element_volume.push_back(volume_m3);
    element_row.push_back(first);
  };
  const auto density_of = [&](const TetRest& rest) {
    return body.materials()[static_cast<size_t>(rest.material)].density_kg_per_m3;
  };
  for (int t = 0; t < mesh.tet_count(); ++t) {
    if (body.cut_tet_index(t) >= 0) continue;
    std::array<int, 4> element_rows{};
    for (size_t j = 0; j < 4; ++j) element_rows[j] = body.dofs().vertex_row[static_cast<size_t>(mesh.tets[static_cast<size_t>(t)][j])];
    element(element_rows, body.elasticity().rest(t).volume_m3, density_of(body.elasticity().rest(t)));
  }
  for (int k = 0; k < body.xfem().cut_tet_count(); ++k) {
    if (body.xfem().retired(k)) continue;
    const Tet& vertices = body.xfem().cut_tets()[static_cast<size_t>(k)].vertices;
    for (int p = 0; p < static_cast<int>(body.xfem().piece_count(k)); ++p) {
      const CutPiece& piece = body.xfem().piece(k, p);
      std::array<int, 4> element_rows{};
      for (size_t j = 0; j < 4; ++j) {
        element_rows[j] = piece.ghost_row[j] >= 0 ? piece.ghost_row[j] : body.dofs().vertex_row[static_cast<size_t>(vertices[j])];
      }
      const TetRest& rest = body.xfem().rest(k);
      element(element_rows, piece.weight * rest.volume_m3, density_of(rest));
    }
  }
  std::vector<int> piece_of(static_cast<size_t>(rows + 1), -1);
  std::vector<BodyPiece> pieces;
  const auto piece_at = [&](int node) -> BodyPiece& {
    const int root = find(node);
    if (piece_of[static_cast<size_t>(root)] < 0) {
      piece_of[static_cast<size_t>(root)] = static_cast<int>(pieces.size());
      pieces.emplace_back();
      pieces.back().held = find(held) == root;
    }
    return pieces[static_cast<size_t>(piece_of[static_cast<size_t>(root)])];
  };
  for (size_t e = 0; e < element_row.size(); ++e) {
    BodyPiece& piece = piece_at(element_row[e]);
    piece.mass_kg += element_mass[e];
    piece.volume_m3 += element_volume[e];
  }
  for (int row = 0; row < rows; ++row) {
    const int root = find(row);
    if (piece_of[static_cast<size_t>(root)] >= 0) pieces[static_cast<size_t>(piece_of[static_cast<size_t>(root)])].rows.push_back(row);
  }
  std::sort(pieces.begin(), pieces.end(), [](const BodyPiece& a, const BodyPiece& b) { return a.mass_kg > b.mass_kg; });
  return pieces;
}

/// 1 in the `axis` component of every row of `piece`: its rigid translation along that axis.
inline Eigen::VectorXd translation(const DeformableBody& body, const BodyPiece& piece, int axis) {
  Eigen::VectorXd c = Eigen::VectorXd::Zero(body.dof_count());
  for (const int row : piece.rows) c(3 * row + axis) = 1.0;
  return c;
}

/// The piece's mean displacement weighted by its rows' lumped masses: its centre of mass minus a
/// constant (the rows' rest positions and the pieces' offsets do not change in time), so its
/// differences in time are those of the centre of mass. [m]
inline Eigen::Vector3d mean_displacement_m(const DeformableBody& body, const BodyPiece& piece,
                                       const Eigen::VectorXd& displacement_m) {
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  double mass = 0.0;
  for (const int row : piece.rows) {
    const double m = body.mass_kg()(3 * row);
    moment += m * Eigen::Vector3d(displacement_m.segment<3>(3 * row));
    mass += m;
  }
  return moment / mass;
}

}  // namespace tissue::xfem_test
