// The bodies a cut body consists of, found from its elements alone (for tests that judge a cut by
// what falls): the core's parts (core/fem/body_parts.hpp: the rows each uncut tet and each live
// cut-tet piece use, joined; a part that holds a fixed vertex is held), each with its mass computed
// from the geometry (rho V of its uncut tets, rho w_p V of its pieces), not from the body's lumped
// masses, so that a test can compare the two.
#pragma once

#include "core/fem/body_parts.hpp"
#include "core/fem/deformable_body.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <vector>

namespace tissue::xfem_test {

struct BodyPiece {
  std::vector<int> rows;  ///< block rows of the unknowns that move it
  bool held = false;      ///< it holds a fixed vertex
  double mass_kg = 0.0;   ///< from the geometry: rho V of its tets and pieces
  double volume_m3 = 0.0;
};

/// The connected pieces of `body` (the core's find_body_parts), largest mass first, each with its
/// mass and volume summed from its elements' geometry.
inline std::vector<BodyPiece> body_pieces(const DeformableBody& body) {
  const TetMesh& mesh = body.mesh();
  const BodyParts parts = find_body_parts(body);
  std::vector<BodyPiece> pieces(static_cast<size_t>(parts.count()));
  int held_piece = -1;
  for (int p = 0; p < parts.count(); ++p) {
    pieces[static_cast<size_t>(p)].held = parts.held[static_cast<size_t>(p)] != 0;
    if (parts.held[static_cast<size_t>(p)] != 0) held_piece = p;
  }
  // An element's piece: that of any of its rows, else (fixed vertices only) the held one.
  const auto element = [&](const std::array<int, 4>& element_rows, double volume_m3, double density) {
    int piece = -1;
    for (const int row : element_rows) {
      if (row >= 0) piece = parts.part_of_row[static_cast<size_t>(row)];
    }
    if (piece < 0) {
      if (held_piece < 0) {
        held_piece = static_cast<int>(pieces.size());
        pieces.emplace_back().held = true;
      }
      piece = held_piece;
    }
    pieces[static_cast<size_t>(piece)].mass_kg += density * volume_m3;
    pieces[static_cast<size_t>(piece)].volume_m3 += volume_m3;
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
    for (int p = 0; p < static_cast<int>(body.xfem().piece_count(k)); ++p) {
      const TetRest& rest = body.xfem().rest(k);
      element(body.piece_rows(k, p), body.xfem().piece(k, p).weight * rest.volume_m3, density_of(rest));
    }
  }
  for (size_t row = 0; row < parts.part_of_row.size(); ++row) {
    const int part = parts.part_of_row[row];
    if (part >= 0) pieces[static_cast<size_t>(part)].rows.push_back(static_cast<int>(row));
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
