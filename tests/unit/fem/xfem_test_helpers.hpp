// What the XFEM tests share: cuts of a mesh by a plane (sides from the signed distance, volume
// fractions by exact clipping of the tet, written here independently of the volume cutter), the
// tangent as a dense matrix, and a Newton solve for static equilibrium.
#pragma once

#include "core/fem/tet_cut.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/mesh/topology.hpp"
#include "core/solve/linear_solver.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

namespace tissue::xfem_test {

/// The plane n . x = offset; "above" is n . x > offset.
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  double offset_m = 0.0;
  [[nodiscard]] double distance(const Eigen::Vector3d& x) const { return normal.dot(x) - offset_m; }
};

/// Volume of a convex polyhedron given by its faces (each a convex polygon, any orientation):
/// pyramids from the centroid of the vertices, which is inside. [m^3]
inline double convex_volume(const std::vector<std::vector<Eigen::Vector3d>>& faces) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& face : faces) {
    for (const auto& p : face) {
      centre += p;
      ++count;
    }
  }
  centre /= count;
  double volume = 0.0;
  for (const auto& face : faces) {
    for (size_t k = 1; k + 1 < face.size(); ++k)
      volume += std::abs(signed_tet_volume(centre, face[0], face[k], face[k + 1]));
  }
  return volume;
}

/// The part of the tet above the plane, clipped face by face (Sutherland-Hodgman), closed by the
/// cap polygon in the plane; its volume over the tet's volume.
inline double clipped_volume_fraction_above(const TetPositions& x, const Plane& plane) {
  constexpr std::array<std::array<int, 3>, 4> FACES{{{0, 1, 2}, {0, 1, 3}, {0, 2, 3}, {1, 2, 3}}};
  std::vector<std::vector<Eigen::Vector3d>> faces;
  std::vector<Eigen::Vector3d> cap;
  for (const auto& face : FACES) {
    std::vector<Eigen::Vector3d> clipped;
    for (size_t k = 0; k < 3; ++k) {
      const Eigen::Vector3d& p = x[static_cast<size_t>(face[k])];
      const Eigen::Vector3d& q = x[static_cast<size_t>(face[(k + 1) % 3])];
      const double dp = plane.distance(p);
      const double dq = plane.distance(q);
      if (dp > 0.0) clipped.push_back(p);
      if ((dp > 0.0) != (dq > 0.0)) {
        const Eigen::Vector3d crossing = p + dp / (dp - dq) * (q - p);
        clipped.push_back(crossing);
        cap.push_back(crossing);
      }
    }
    if (clipped.size() >= 3) faces.push_back(clipped);
  }
  // Each crossing was found from both faces of its edge: keep one, order them around their centre.
  std::vector<Eigen::Vector3d> unique;
  for (const auto& p : cap) {
    if (std::none_of(unique.begin(), unique.end(), [&](const Eigen::Vector3d& u) { return (u - p).norm() < 1e-15; })) {
      unique.push_back(p);
    }
  }
  if (unique.size() >= 3) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const auto& p : unique) centre += p / static_cast<double>(unique.size());
    const Eigen::Vector3d e1 = (unique[0] - centre).normalized();
    const Eigen::Vector3d e2 = plane.normal.normalized().cross(e1);
    std::sort(unique.begin(), unique.end(), [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
      return std::atan2((a - centre).dot(e2), (a - centre).dot(e1)) <
             std::atan2((b - centre).dot(e2), (b - centre).dot(e1));
    });
    faces.push_back(unique);
  }
  const double total = std::abs(signed_tet_volume(x[0], x[1], x[2], x[3]));
  return faces.empty() ? 0.0 : convex_volume(faces) / total;
}

inline TetPositions tet_positions(const TetMesh& mesh, int tet) {
  TetPositions x;
  for (size_t i = 0; i < 4; ++i)
    x[i] = mesh.rest_positions_m[static_cast<size_t>(mesh.tets[static_cast<size_t>(tet)][i])];
  return x;
}

/// The cut of a tet by the plane, or nothing when all its vertices lie on one side.
inline std::optional<TetCut> plane_tet_cut(const TetMesh& mesh, int tet, const Plane& plane, int cut_id = 0) {
  const TetPositions x = tet_positions(mesh, tet);
  TetCut cut;
  cut.tet = tet;
  cut.cut_id = cut_id;
  std::array<double, 4> d{};
  for (size_t i = 0; i < 4; ++i) {
    d[i] = plane.distance(x[i]);
    cut.side[i] = d[i] > 0.0 ? 1 : -1;
  }
  if (std::all_of(cut.side.begin(), cut.side.end(), [&](std::int8_t s) { return s == cut.side[0]; }))
    return std::nullopt;
  for (size_t k = 0; k < 6; ++k) {
    const size_t i = static_cast<size_t>(TET_EDGES[k][0]);
    const size_t j = static_cast<size_t>(TET_EDGES[k][1]);
    if (cut.side[i] != cut.side[j]) cut.edge_ratio[k] = d[i] / (d[i] - d[j]);
  }
  cut.volume_fraction_above = clipped_volume_fraction_above(x, plane);
  return cut;
}

/// Cuts of every tet the plane crosses and `keep` accepts (all when empty).
inline std::vector<TetCut> plane_cuts(const TetMesh& mesh, const Plane& plane, int cut_id = 0,
                                      const std::function<bool(int)>& keep = {}) {
  std::vector<TetCut> cuts;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    if (keep && !keep(t)) continue;
    if (auto cut = plane_tet_cut(mesh, t, plane, cut_id)) cuts.push_back(*cut);
  }
  return cuts;
}

/// The whole matrix, dense.
inline Eigen::MatrixXd dense(const BlockSparseMatrix& matrix) {
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(matrix.rows(), matrix.rows());
  for (int r = 0; r < matrix.block_rows(); ++r) {
    for (int s = matrix.row_begin(r); s < matrix.row_begin(r) + matrix.row_size(r); ++s) {
      a.block<3, 3>(3 * r, 3 * matrix.slot_column(s)) += matrix.block(s);
    }
  }
  return a;
}

/// Newton's method for f_int(u) = f_ext (CHOLMOD on the tangent), from `displacement_m`; returns
/// the relative residual reached.
inline double solve_static(DeformableBody& body, Eigen::VectorXd& displacement_m, int max_iterations = 30) {
  CholmodSolver solver;
  const Eigen::VectorXd no_mass = Eigen::VectorXd::Zero(body.dof_count());
  Eigen::VectorXd force;
  Eigen::VectorXd step(body.dof_count());
  double relative = 1.0;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    body.evaluate(displacement_m, force, /*update_tangent=*/true);
    const Eigen::VectorXd residual = body.external_force_n() - force;
    relative = residual.norm() / std::max(body.external_force_n().norm(), 1e-300);
    if (relative < 1e-12) break;
    step.setZero();
    solver.solve(ShiftedSystem{&body.tangent(), 1.0, &no_mass}, residual, step);
    displacement_m += step;
  }
  return relative;
}

}  // namespace tissue::xfem_test
