// Tests of the cut-tet mechanics (dissertation 3.3, 4.2.1-4.2.3): the force equals eq. 3.30 written
// with 12x12 matrices and is the gradient of the weighted energy; the tangent equals finite
// differences where it is exact and the linear K^X of eq. 3.19-3.23 at rest; enriching a deformed
// body leaves its u forces, u tangent and energy unchanged; enriched unknowns are listed once, fixed
// vertices get one too; the enriched mass is the mass across the cut; bad cuts are refused.
#include "core/fem/deformable_body.hpp"
#include "core/mesh/box_mesh.hpp"
#include "fem/xfem_test_helpers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <tuple>

namespace tissue {
namespace {

using xfem_test::dense;
using xfem_test::Plane;

using Matrix24d = Eigen::Matrix<double, 24, 24>;
using Vector24d = Eigen::Matrix<double, 24, 1>;

const Material MATERIAL{1.0e5, 0.4, 1000.0};

TetMesh one_tet() {
  TetMesh mesh;
  mesh.rest_positions_m = {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.011, 0.001, -0.002),
                           Eigen::Vector3d(0.002, 0.009, 0.001), Eigen::Vector3d(-0.001, 0.002, 0.012)};
  mesh.tets = {Tet{0, 1, 2, 3}};
  return mesh;
}

// Rotations converged to ~1e-12 rad (the rule before issue 12; the default stops at 1e-6 rad): the
// identities below compare parts and tets whose rotations came from different warm starts, to round-off.
constexpr double CONVERGED_ROTATION_RAD = 4e-18;

BodySettings free_settings() {
  BodySettings settings;
  settings.material = MATERIAL;
  settings.gravity_m_per_s2.setZero();
  settings.rotation.max_error_rad = CONVERGED_ROTATION_RAD;
  return settings;
}

Vector12d flatten(const TetPositions& x) {
  Vector12d flat;
  for (int i = 0; i < 4; ++i) flat.segment<3>(3 * i) = x[static_cast<size_t>(i)];
  return flat;
}

Matrix12d block_diagonal(const Eigen::Matrix3d& r) {
  Matrix12d b = Matrix12d::Zero();
  for (int i = 0; i < 4; ++i) b.block<3, 3>(3 * i, 3 * i) = r;
  return b;
}

// One tet, nothing fixed, cut with the given sides. The body's unknowns are [u_0..u_3, c_0..c_3]
// (24; the ghosts are made in local-vertex order): c_j moves the copy of vertex j that the part
// across the cut uses, X_j + c_j. The dissertation's are [u, a] with that copy at X_j + u_j + Psi a_j,
// Psi = -H_j: c = u - H a, a change of variables q_body = T q. The tests below speak the
// dissertation's (force(), tangent() and energy() take and give [u, a]: f = T^T f_body, K = T^T K_body
// T), so its equations stay the reference; PartPositionsAreRealVerticesAndGhostCopies checks T.
struct CutOneTet {
  TetMesh mesh = one_tet();
  DeformableBody body{mesh, free_settings()};
  TetCut cut;
  Matrix24d to_body = Matrix24d::Identity();  // T

  CutOneTet(std::array<std::int8_t, 4> side, double fraction_above) {
    cut.tet = 0;
    cut.side = side;
    cut.volume_fraction_above = fraction_above;
    body.enrich(cut);
    for (int j = 0; j < 4; ++j) {
      to_body.block<3, 3>(12 + 3 * j, 3 * j) = Eigen::Matrix3d::Identity();
      to_body.block<3, 3>(12 + 3 * j, 12 + 3 * j) = -side[static_cast<size_t>(j)] * Eigen::Matrix3d::Identity();
    }
  }
  [[nodiscard]] double psi(int i, CutPart part) const {
    return enrichment_shift(cut.side[static_cast<size_t>(i)], part);
  }
  [[nodiscard]] double weight(CutPart part) const {
    return part == CutPart::above ? cut.volume_fraction_above : 1.0 - cut.volume_fraction_above;
  }
  Vector24d force(const Vector24d& q) {
    Eigen::VectorXd f;
    body.evaluate(Eigen::VectorXd(to_body * q), f, /*update_tangent=*/true);
    return to_body.transpose() * f;
  }
  Matrix24d tangent() const { return to_body.transpose() * dense(body.tangent()) * to_body; }
  [[nodiscard]] double energy(const Vector24d& q) { return body.elastic_energy_j(Eigen::VectorXd(to_body * q)); }

  // The unknowns that put part a at `above` and part b at `below` (vertex positions): the real
  // vertex of each side is its own part's vertex, and a_j = p_aj - p_bj (from eq. 3.26-3.27).
  [[nodiscard]] Vector24d unknowns_for_parts(const TetPositions& above, const TetPositions& below) const {
    Vector24d q;
    for (size_t j = 0; j < 4; ++j) {
      const Eigen::Vector3d& own = cut.side[j] == 1 ? above[j] : below[j];
      q.segment<3>(3 * static_cast<Eigen::Index>(j)) = own - mesh.rest_positions_m[j];
      q.segment<3>(12 + 3 * static_cast<Eigen::Index>(j)) = above[j] - below[j];
    }
    return q;
  }

  // Eq. 3.30 with 12x12 matrices: f^X = sum_p w_p S_p^T R_p K_e (R_p^T p_p - p0), S_p = [I, diag(Psi_p)],
  // p_p = p0 + u + Psi_p a; R_p from the SVD (the reference, independent of the model's Newton).
  [[nodiscard]] Vector24d reference_force(const Vector24d& q) const {
    const TetRest& rest = body.elasticity().rest(0);
    const Matrix12d k_e = linear_stiffness_matrix(rest, body.elasticity().lame()[0]);
    TetPositions rest_x;
    for (size_t j = 0; j < 4; ++j) rest_x[j] = mesh.rest_positions_m[j];
    const Vector12d p0 = flatten(rest_x);
    Vector24d f = Vector24d::Zero();
    for (const CutPart part : {CutPart::above, CutPart::below}) {
      Eigen::Matrix<double, 12, 24> s = Eigen::Matrix<double, 12, 24>::Zero();
      s.leftCols<12>().setIdentity();
      for (int j = 0; j < 4; ++j) s.block<3, 3>(3 * j, 12 + 3 * j) = psi(j, part) * Eigen::Matrix3d::Identity();
      const Vector12d p = p0 + s * q;
      TetPositions p_tet;
      for (size_t j = 0; j < 4; ++j) p_tet[j] = p.segment<3>(3 * static_cast<Eigen::Index>(j));
      const Matrix12d r = block_diagonal(rotation_by_svd(deformation_gradient(rest, p_tet)));
      f += weight(part) * s.transpose() * (r * k_e * (r.transpose() * p - p0));
    }
    return f;
  }
};

TetPositions moved(const TetMesh& mesh, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& shift) {
  TetPositions x;
  for (size_t j = 0; j < 4; ++j) x[j] = rotation * mesh.rest_positions_m[j] + shift;
  return x;
}

const std::array<std::array<std::int8_t, 4>, 3> SIDE_PATTERNS{{{1, 1, -1, -1}, {1, -1, -1, -1}, {-1, 1, 1, 1}}};

TEST(XfemCutTet, ForceEqualsEquation330WithSeparateRotations) {
  // Parts a and b turned by different large rotations, strained by up to 20% (jitter 2 mm on
  // 1 cm edges). Both sides compute the same sums from the same K_e entries; the rotations agree
  // to the Newton tolerance (angle error ~1e-12), so 1e-12 relative bounds both (measured: 1.4e-14).
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.002, 0.002);
  for (const auto& side : SIDE_PATTERNS) {
    CutOneTet tet(side, 0.37);
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::Matrix3d ra =
          Eigen::AngleAxisd(0.4 + 0.5 * trial, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
      const Eigen::Matrix3d rb =
          Eigen::AngleAxisd(-0.9 + 0.3 * trial, Eigen::Vector3d(-1, 0.3, 2).normalized()).toRotationMatrix();
      TetPositions above = moved(tet.mesh, ra, Eigen::Vector3d(0.01, 0.0, 0.0));
      TetPositions below = moved(tet.mesh, rb, Eigen::Vector3d(0.0, -0.02, 0.0));
      for (size_t j = 0; j < 4; ++j) {
        for (int c = 0; c < 3; ++c) {
          above[j](c) += jitter(rng);
          below[j](c) += jitter(rng);
        }
      }
      const Vector24d q = tet.unknowns_for_parts(above, below);
      const Vector24d f = tet.force(q);
      const Vector24d expected = tet.reference_force(q);
      EXPECT_LT((f - expected).norm(), 1e-12 * expected.norm()) << "trial " << trial;
      // The enriched forces are not an afterthought: they carry a good share of the total.
      EXPECT_GT(f.tail<12>().norm(), 0.1 * f.head<12>().norm());
    }
  }
}

TEST(XfemCutTet, ForceIsTheGradientOfTheWeightedEnergy) {
  // With the polar rotation, V R sigma g_i is the exact gradient of the co-rotated energy, so f^X is
  // the gradient of w_a E(p_a) + w_b E(p_b) in the 24 unknowns at any state. Central differences
  // with step 1e-7 m: truncation ~step^2 f''' and round-off ~1e-16 E / step stay below 1e-8 of |f|
  // (measured: 2e-11).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.002, 0.002);
  CutOneTet tet({1, -1, 1, -1}, 0.62);
  Vector24d q;
  for (int k = 0; k < 24; ++k) q(k) = jitter(rng);
  const Vector24d f = tet.force(q);
  Vector24d numeric;
  const double step_m = 1e-7;
  for (int k = 0; k < 24; ++k) {
    Vector24d plus = q;
    Vector24d minus = q;
    plus(k) += step_m;
    minus(k) -= step_m;
    numeric(k) = (tet.energy(plus) - tet.energy(minus)) / (2.0 * step_m);
  }
  EXPECT_LT((numeric - f).norm(), 1e-8 * f.norm());
}

TEST(XfemCutTet, TangentMatchesFiniteDifferencesAtRotatedRestStatesOfBothParts) {
  // Each part rigidly moved (different rotations): both parts' rotated strains vanish, so the
  // dR/dx terms the tangent (eq. 4.3-4.6) leaves out vanish too and it is the exact derivative.
  // Tolerance as for the uncut tet (test_corotational): 1e-6 relative.
  for (const auto& side : SIDE_PATTERNS) {
    CutOneTet tet(side, 0.25);
    const Eigen::Matrix3d ra = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
    const Eigen::Matrix3d rb = Eigen::AngleAxisd(-0.7, Eigen::Vector3d(0, 1, 2).normalized()).toRotationMatrix();
    const Vector24d q = tet.unknowns_for_parts(moved(tet.mesh, ra, Eigen::Vector3d(0.01, 0.0, 0.0)),
                                               moved(tet.mesh, rb, Eigen::Vector3d(0.0, 0.0, -0.005)));
    tet.force(q);
    const Matrix24d analytic = tet.tangent();
    Matrix24d numeric;
    const double step_m = 1e-7;
    for (int k = 0; k < 24; ++k) {
      Vector24d plus = q;
      Vector24d minus = q;
      plus(k) += step_m;
      minus(k) -= step_m;
      numeric.col(k) = (tet.force(plus) - tet.force(minus)) / (2.0 * step_m);
    }
    EXPECT_LT((numeric - analytic).norm(), 1e-6 * analytic.norm());
    EXPECT_LT((analytic - analytic.transpose()).norm(), 1e-12 * analytic.norm());
  }
}

TEST(XfemCutTet, TangentAtRestIsTheLinearXfemStiffness) {
  // At rest R_a = R_b = I and eq. 4.3-4.6 reduce to the linear K^X of eq. 3.19-3.23, written here
  // in its case form.
  for (const auto& side : SIDE_PATTERNS) {
    const double w_a = 0.3;
    const double w_b = 1.0 - w_a;
    CutOneTet tet(side, w_a);
    tet.force(Vector24d::Zero());
    const Matrix12d k = linear_stiffness_matrix(tet.body.elasticity().rest(0), tet.body.elasticity().lame()[0]);
    Matrix24d expected = Matrix24d::Zero();
    const auto side_factor = [&](int h) { return h == 1 ? -w_b : w_a; };  // eq. 3.21-3.22
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) {
        const Eigen::Matrix3d k_ij = k.block<3, 3>(3 * i, 3 * j);
        const int h_i = side[static_cast<size_t>(i)];
        const int h_j = side[static_cast<size_t>(j)];
        expected.block<3, 3>(3 * i, 3 * j) = k_ij;
        expected.block<3, 3>(3 * i, 12 + 3 * j) = side_factor(h_j) * k_ij;
        expected.block<3, 3>(12 + 3 * i, 3 * j) = side_factor(h_i) * k_ij;
        const double aa = h_i != h_j ? 0.0 : (h_i == 1 ? w_b : w_a);  // eq. 3.23
        expected.block<3, 3>(12 + 3 * i, 12 + 3 * j) = aa * k_ij;
      }
    }
    EXPECT_LT((tet.tangent() - expected).norm(), 1e-12 * expected.norm());
  }
}

TEST(XfemCutTet, PartPositionsAreRealVerticesAndGhostCopies) {
  CutOneTet tet({1, -1, 1, -1}, 0.5);
  Vector24d q;
  for (int k = 0; k < 24; ++k) q(k) = 0.001 * k;
  const TetPositions above = tet.body.part_positions(q, 0, CutPart::above);
  const TetPositions below = tet.body.part_positions(q, 0, CutPart::below);
  const Vector24d dissertation = tet.to_body.inverse() * q;  // [u, a]
  for (size_t j = 0; j < 4; ++j) {
    const Eigen::Vector3d rest = tet.mesh.rest_positions_m[j];
    const Eigen::Vector3d x = rest + q.segment<3>(3 * static_cast<Eigen::Index>(j));
    const Eigen::Vector3d copy = rest + q.segment<3>(12 + 3 * static_cast<Eigen::Index>(j));
    // Each part: its own side's vertices real, the others the ghost copy X + c.
    EXPECT_EQ(above[j], tet.cut.side[j] == 1 ? x : copy);
    EXPECT_EQ(below[j], tet.cut.side[j] == -1 ? x : copy);
    // ... which is the dissertation's x + a above and x - a below (eq. 3.26-3.27).
    const Eigen::Vector3d a = dissertation.segment<3>(12 + 3 * static_cast<Eigen::Index>(j));
    const Eigen::Vector3d expected = tet.cut.side[j] == 1 ? Eigen::Vector3d(x - a) : Eigen::Vector3d(x + a);
    EXPECT_LT((copy - expected).norm(), 1e-15);
  }
}

// --- Enriching a body ---

// A 4x2x2 box of 1 cm cubes fixed at x = 0, deformed by a random field with a large rotation.
struct Box {
  TetMesh mesh = make_box_mesh(4, 2, 2, 0.01);
  DeformableBody body{mesh, settings(mesh)};

  static BodySettings settings(const TetMesh& mesh) {
    BodySettings s;
    s.material = MATERIAL;
    s.rotation.max_error_rad = CONVERGED_ROTATION_RAD;
    s.gravity_m_per_s2 = Eigen::Vector3d(0.0, 0.0, -9.81);
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      if (mesh.rest_positions_m[static_cast<size_t>(v)].x() < 1e-9) s.fixed_vertices.push_back(v);
    }
    return s;
  }
  Eigen::VectorXd deformed(double angle_rad) const {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> jitter(-0.0005, 0.0005);
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(angle_rad, Eigen::Vector3d(0.3, 1, 0.2).normalized()).toRotationMatrix();
    Eigen::VectorXd u(body.dof_count());
    for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
      const Eigen::Vector3d x =
          mesh.rest_positions_m[static_cast<size_t>(body.dofs().row_vertex[static_cast<size_t>(row)])];
      u.segment<3>(3 * row) = r * x - x + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
    }
    return u;
  }
};

// sum over the cut tets of w_across(i) [R K_e (R^T x - X)]_i on the ghost of each vertex, with the
// tet's (uncut) SVD rotation: what the ghosts' forces must be where every ghost is a copy of its
// vertex and both parts are the deformed tet (w_across: the weight of the part that uses the ghost).
Eigen::VectorXd expected_ghost_forces(const DeformableBody& body, const Eigen::VectorXd& positions_m) {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * body.enriched_dof_count());
  const int u_rows = body.dofs().free_vertex_count();
  for (const CutTet& cut_tet : body.cut_tets()) {
    const TetRest& rest = body.elasticity().rest(cut_tet.cut.tet);
    TetPositions x;
    TetPositions x0;
    for (size_t j = 0; j < 4; ++j) {
      x[j] = positions_m.segment<3>(3 * cut_tet.vertices[j]);
      x0[j] = body.mesh().rest_positions_m[static_cast<size_t>(cut_tet.vertices[j])];
    }
    const Matrix12d r = block_diagonal(rotation_by_svd(deformation_gradient(rest, x)));
    const Vector12d tet_force =
        r * linear_stiffness_matrix(rest, body.elasticity().lame()[0]) * (r.transpose() * flatten(x) - flatten(x0));
    for (int i = 0; i < 4; ++i) {
      const double across = cut_tet.cut.side[static_cast<size_t>(i)] == 1 ? cut_tet.weight_below : cut_tet.weight_above;
      f.segment<3>(3 * (cut_tet.enriched_row[static_cast<size_t>(i)] - u_rows)) += across * tet_force.segment<3>(3 * i);
    }
  }
  return f;
}

// S: the body's unknowns after a cut from the u before it, every copy of a vertex moved with it
// (ghosts of a fixed vertex stay). S^T f sums each vertex's copies' forces; S^T K S is the stiffness
// the vertices see while no crack opens.
Eigen::MatrixXd copies_of_vertices(const DeformableBody& body) {
  const int u_rows = body.dofs().free_vertex_count();
  Eigen::MatrixXd s = Eigen::MatrixXd::Zero(body.dof_count(), 3 * u_rows);
  s.topLeftCorner(3 * u_rows, 3 * u_rows).setIdentity();
  for (const EnrichedDof& dof : body.enriched_dofs()) {
    const int vertex_row = body.dofs().vertex_row[static_cast<size_t>(dof.vertex)];
    if (vertex_row >= 0) s.block<3, 3>(3 * dof.row, 3 * vertex_row).setIdentity();
  }
  return s;
}

// The step's own pass finds the potential energy at its displacement (the energy guard's start,
// issue 41: a pass over the elements saved): the uncut tets', the pieces' (ghosts moved apart, so
// that the parts turn differently), gravity's, as potential_energy_j gives it, to round-off. A cut
// leaves it unknown until the next pass.
TEST(XfemEnrich, TheStepsPassFindsThePotentialEnergy) {
  Box box;
  EXPECT_TRUE(std::isnan(box.body.potential_energy_at_last_evaluate_j()));
  const Eigen::VectorXd u = box.deformed(0.8);
  Eigen::VectorXd f;
  box.body.evaluate(u, f, true);
  EXPECT_TRUE(std::isnan(box.body.potential_energy_at_last_evaluate_j()));  // not asked for
  box.body.evaluate_with_potential(u, f, true);
  const double uncut_j = box.body.potential_energy_j(u);
  ASSERT_GT(std::abs(uncut_j), 0.0);
  EXPECT_NEAR(box.body.potential_energy_at_last_evaluate_j(), uncut_j, 1e-12 * std::abs(uncut_j));

  DynamicState state{u, Eigen::VectorXd::Zero(u.size())};
  box.body.enrich(xfem_test::plane_cuts(box.mesh, Plane{Eigen::Vector3d(1, 0.2, 0.1).normalized(), 0.0213}), state);
  EXPECT_TRUE(std::isnan(box.body.potential_energy_at_last_evaluate_j()));
  Eigen::VectorXd moved = state.displacement_m;
  for (Eigen::Index i = u.size(); i < moved.size(); ++i) moved[i] += 0.0004 * std::sin(1.7 * static_cast<double>(i));
  box.body.evaluate_with_potential(moved, f, false);
  const double cut_j = box.body.potential_energy_j(moved);
  EXPECT_NEAR(box.body.potential_energy_at_last_evaluate_j(), cut_j, 1e-12 * std::abs(cut_j));
  EXPECT_GT(std::abs(cut_j - uncut_j), 1e-6 * std::abs(uncut_j));  // the pieces moved: another energy
}

// A sliver cut off a tet's corner (~1e-4 of its volume) spinning 0.3 rad: a linearized step strays by
// ~ w V theta^2, so it counts as a whole tet turning sqrt(w) theta (issue 41: slivers at a cut's
// front set off Newton corrections of the whole body on cut steps); the other piece does not turn.
TEST(XfemEnrich, ASliverTurnsTheStepAsAWholeTetTurningSqrtOfItsShare) {
  const TetMesh mesh = one_tet();
  DeformableBody body(mesh, free_settings());
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count())};
  body.enrich(xfem_test::plane_cuts(mesh, Plane{Eigen::Vector3d::UnitZ(), 0.0115}), state);
  ASSERT_EQ(body.cut_tets().size(), 1U);
  const CutTet& cut = body.cut_tets()[0];
  const double sliver = std::min(cut.weight_above, cut.weight_below);
  ASSERT_LT(sliver, 1e-3);
  Eigen::VectorXd f;
  body.evaluate(state.displacement_m, f, false);  // the rotations the turn is measured from
  const double angle_rad = 0.3;
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(angle_rad, Eigen::Vector3d(1, 2, 0.5).normalized()).toRotationMatrix();
  // Vertex 3 alone is above the plane: the sliver is vertex 3 and the ghosts of 0, 1 and 2.
  const Eigen::Vector3d tip = mesh.rest_positions_m[3];
  Eigen::VectorXd increment = Eigen::VectorXd::Zero(body.dof_count());
  for (size_t i = 0; i < 3; ++i) {
    increment.segment<3>(3 * cut.enriched_row[i]) = (turn - Eigen::Matrix3d::Identity()) * (mesh.rest_positions_m[i] - tip);
  }
  const double expected_rad = std::sqrt(sliver) * std::sin(angle_rad);  // |axial(skew(R - I))| = sin
  EXPECT_NEAR(body.largest_turn_rad(increment, 0.0), expected_rad, 1e-9 * expected_rad);
}

// The predicted step's guard asks two turns (h (v1 - v0) and h v1) in one pass over the elements:
// each is what largest_turn_rad gives, bitwise, uncut tets and pieces alike, whichever of the two
// passes its bound.
TEST(XfemEnrich, TwoTurnsInOnePassAreEachTheTurnAlone) {
  Box box;
  DynamicState state{box.deformed(0.8), Eigen::VectorXd::Zero(box.body.dof_count())};
  box.body.enrich(xfem_test::plane_cuts(box.mesh, Plane{Eigen::Vector3d(1, 0.2, 0.1).normalized(), 0.0213}), state);
  ASSERT_GT(box.body.cut_tets().size(), 0U);
  Eigen::VectorXd f;
  box.body.evaluate(state.displacement_m, f, false);  // the rotations the turns are measured from
  const Eigen::Index n = box.body.dof_count();
  Eigen::VectorXd first(n), second(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    first[i] = 1e-4 * std::sin(1.7 * static_cast<double>(i));
    second[i] = 2e-4 * std::cos(0.9 * static_cast<double>(i) + 0.3);
  }
  const double first_rad = box.body.largest_turn_rad(first, 0.0);
  const double second_rad = box.body.largest_turn_rad(second, 0.0);
  ASSERT_GT(first_rad, 0.0);
  ASSERT_NE(first_rad, second_rad);
  const auto expect_alone = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b, double resolution_a_rad,
                                double resolution_b_rad) {
    const std::array<double, 2> turns = box.body.largest_turns_rad(a, b, {resolution_a_rad, resolution_b_rad});
    EXPECT_EQ(turns[0], box.body.largest_turn_rad(a, resolution_a_rad));
    EXPECT_EQ(turns[1], box.body.largest_turn_rad(b, resolution_b_rad));
  };
  expect_alone(first, second, 0.0, 0.0);  // both past their bounds: the fused pass
  expect_alone(second, first, 0.0, 0.0);
  expect_alone(first, second, 1e9, 0.0);  // one under its bound: that bound, the other's pass
  expect_alone(first, second, 0.0, 1e9);
  expect_alone(first, second, 1e9, 1e9);
}

TEST(XfemEnrich, AtADeformedStateKeepsForcesTangentAndEnergy) {
  // A cut of a running body makes each ghost a copy of its vertex (displacement and velocity), so
  // both parts are the deformed tet and R_a = R_b = R: nothing moves, the energy is unchanged, and
  // each vertex's copies share out its force (w_own F_i on u, w_across F_i on the ghost) and
  // stiffness (to round-off: 1e-12 relative). The ghosts' forces are not zero in a stressed state:
  // they are the crack-opening forces, zero only where the body is unstressed (rigid motion).
  Box box;
  const Eigen::VectorXd u = box.deformed(0.8);
  Eigen::VectorXd f_before;
  box.body.evaluate(u, f_before, true);
  const Eigen::MatrixXd k_before = dense(box.body.tangent());
  const double energy_before = box.body.elastic_energy_j(u);

  const auto cuts = xfem_test::plane_cuts(box.mesh, Plane{Eigen::Vector3d(1, 0.2, 0.1).normalized(), 0.0213});
  ASSERT_GE(cuts.size(), 10u);
  DynamicState state{u, Eigen::VectorXd::Zero(u.size())};
  box.body.enrich(cuts, state);
  EXPECT_EQ(state.displacement_m.head(u.size()), u);
  const Eigen::MatrixXd s = copies_of_vertices(box.body);
  for (const EnrichedDof& dof : box.body.enriched_dofs()) {
    const int vertex_row = box.body.dofs().vertex_row[static_cast<size_t>(dof.vertex)];
    const Eigen::Vector3d copy_of = vertex_row >= 0 ? Eigen::Vector3d(u.segment<3>(3 * vertex_row)) : Eigen::Vector3d::Zero();
    EXPECT_EQ(Eigen::Vector3d(state.displacement_m.segment<3>(3 * dof.row)), copy_of);
  }

  Eigen::VectorXd f_after;
  box.body.evaluate(state.displacement_m, f_after, true);
  const Eigen::MatrixXd k_after = dense(box.body.tangent());
  const Eigen::Index n_u = u.size();
  EXPECT_LT((s.transpose() * f_after - f_before).norm(), 1e-12 * f_before.norm());
  EXPECT_LT((s.transpose() * k_after * s - k_before).norm(), 1e-12 * k_before.norm());
  EXPECT_NEAR(box.body.elastic_energy_j(state.displacement_m), energy_before, 1e-12 * energy_before);

  Eigen::VectorXd positions;
  box.body.positions(state.displacement_m, positions);
  const Eigen::VectorXd expected = expected_ghost_forces(box.body, positions);
  EXPECT_LT((f_after.tail(f_after.size() - n_u) - expected).norm(), 1e-12 * expected.norm());
  EXPECT_GT(expected.norm(), 0.01 * f_before.norm());  // the crack-opening forces are real
}

TEST(XfemEnrich, ATetJoiningAMovedUnknownStartsAsTheTetWas) {
  // A stroke completes its tets over several steps: the later ones share the ghosts of the earlier
  // ones, which have moved since. The joining tet's parts must start as the tet was: elastic energy
  // and each vertex's force over its copies unchanged by the enrichment (to round-off, 1e-12
  // relative; without the offsets the parts would start where the ghosts are: +9e-5 J here), no
  // kinetic energy gained and the momentum kept (the join is inelastic: the joining material
  // brings its momentum to the ghost).
  Box box;
  const auto cuts = xfem_test::plane_cuts(box.mesh, Plane{Eigen::Vector3d(1, 0.2, 0.1).normalized(), 0.0213});
  ASSERT_GE(cuts.size(), 10u);
  const size_t half = cuts.size() / 2;
  DynamicState state{box.deformed(0.8), Eigen::VectorXd::Zero(box.body.dof_count())};
  box.body.enrich(std::span(cuts).first(half), state);

  // The earlier tets' parts move apart: every ghost displaced from its vertex and moving.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> spread(-1.0, 1.0);
  const Eigen::Index n_u = 3 * box.body.dofs().free_vertex_count();
  for (Eigen::Index k = n_u; k < state.displacement_m.size(); ++k) {
    state.displacement_m(k) += 0.0008 * spread(rng);
    state.velocity_m_per_s(k) = 0.05 * spread(rng);
  }
  for (Eigen::Index k = 0; k < n_u; ++k) state.velocity_m_per_s(k) = 0.05 * spread(rng);
  Eigen::VectorXd f_before;
  box.body.evaluate(state.displacement_m, f_before, false);
  const Eigen::VectorXd momentum_before = box.body.mass_kg().cwiseProduct(state.velocity_m_per_s);
  const double energy_before = box.body.elastic_energy_j(state.displacement_m);
  const double kinetic_before = box.body.kinetic_energy_j(state.velocity_m_per_s);
  const Eigen::VectorXd velocity_before = state.velocity_m_per_s;
  const Eigen::VectorXd displacement_before = state.displacement_m;

  const EnrichmentResult result = box.body.enrich(std::span(cuts).subspan(half), state);
  ASSERT_LT(result.new_enriched_dofs, 4 * static_cast<int>(cuts.size() - half));  // some are joined
  int joined = 0;
  for (size_t c = half; c < cuts.size(); ++c) {
    for (const Eigen::Vector3d& offset : box.body.cut_tets()[c].enrichment_offset_m) joined += offset.norm() > 0.0;
  }
  EXPECT_GT(joined, 0);

  Eigen::VectorXd f_after;
  box.body.evaluate(state.displacement_m, f_after, false);
  EXPECT_NEAR(box.body.elastic_energy_j(state.displacement_m), energy_before, 1e-12 * energy_before);
  // Each vertex's copies: the old ghosts' forces, plus the joining tets' forces shared out.
  const Eigen::MatrixXd s = copies_of_vertices(box.body);
  const Eigen::MatrixXd s_before = s.topRows(f_before.size());
  EXPECT_LT((s.transpose() * f_after - s_before.transpose() * f_before).norm(), 1e-12 * f_before.norm());
  EXPECT_LE(box.body.kinetic_energy_j(state.velocity_m_per_s), kinetic_before * (1.0 + 1e-12));
  const Eigen::VectorXd momentum_after = box.body.mass_kg().cwiseProduct(state.velocity_m_per_s);
  for (int axis = 0; axis < 3; ++axis) {  // the total momentum, each axis
    double before = 0.0;
    double after = 0.0;
    for (Eigen::Index k = axis; k < momentum_before.size(); k += 3) before += momentum_before(k);
    for (Eigen::Index k = axis; k < momentum_after.size(); k += 3) after += momentum_after(k);
    EXPECT_NEAR(after, before, 1e-12 * momentum_before.cwiseAbs().sum()) << "axis " << axis;
  }
  EXPECT_EQ(state.velocity_m_per_s.head(n_u), velocity_before.head(n_u));  // real vertices untouched
  EXPECT_EQ(state.displacement_m.head(displacement_before.size()), displacement_before);  // nothing moved
}

TEST(XfemEnrich, UnstressedBodyFeelsNoEnrichedForce) {
  // A rigid motion: every tet and part is stress-free, so all forces vanish. Scale of a 1% strain:
  // E 0.01 (1 cm)^2 = 1e-3 N. What remains is the rotation's Newton tolerance (angle error ~1e-12,
  // strain 1e-12, 1e-11 N per tet) and round-off: 1e-10 N overall (measured: 4.5e-13 N).
  const TetMesh mesh = make_box_mesh(3, 2, 2, 0.01);
  DeformableBody body(mesh, free_settings());
  body.enrich(xfem_test::plane_cuts(mesh, Plane{Eigen::Vector3d(1, -0.3, 0.2).normalized(), 0.0151}));
  ASSERT_GT(body.enriched_dof_count(), 0);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::VectorXd q = Eigen::VectorXd::Zero(body.dof_count());
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector3d x = mesh.rest_positions_m[static_cast<size_t>(v)];
    q.segment<3>(3 * v) = r * x - x + Eigen::Vector3d(0.1, -0.2, 0.3);
  }
  for (const EnrichedDof& dof : body.enriched_dofs()) {  // the copies move with their vertices
    q.segment<3>(3 * dof.row) = q.segment<3>(3 * dof.vertex);
  }
  Eigen::VectorXd f;
  body.evaluate(q, f, false);
  EXPECT_LT(f.norm(), 1e-10);
}

TEST(XfemEnrich, ListsEnrichedVerticesOnceAndGivesFixedVerticesARow) {
  Box box;
  // x = 0.004 cuts the first layer of cubes, whose tets touch the fixed face x = 0.
  const auto cuts = xfem_test::plane_cuts(box.mesh, Plane{Eigen::Vector3d::UnitX(), 0.004});
  std::set<int> cut_vertices;
  for (const TetCut& cut : cuts) {
    for (int v : box.mesh.tets[static_cast<size_t>(cut.tet)]) cut_vertices.insert(v);
  }
  const int u_rows = box.body.dofs().free_vertex_count();
  const EnrichmentResult result = box.body.enrich(cuts);
  EXPECT_EQ(result.new_cut_tets, static_cast<int>(cuts.size()));
  EXPECT_EQ(result.new_enriched_dofs, static_cast<int>(cut_vertices.size()));  // once, however many tets share it
  EXPECT_EQ(box.body.enriched_dof_count(), static_cast<int>(cut_vertices.size()));
  EXPECT_EQ(box.body.dof_count(), 3 * (u_rows + static_cast<int>(cut_vertices.size())));
  EXPECT_EQ(box.body.tangent().block_rows(), u_rows + box.body.enriched_dof_count());
  EXPECT_EQ(box.body.mesh().tet_count(), 4 * 2 * 2 * 5);  // the mesh is never remeshed

  int fixed_enriched = 0;
  for (int k = 0; k < box.body.enriched_dof_count(); ++k) {
    const EnrichedDof& dof = box.body.enriched_dofs()[static_cast<size_t>(k)];
    EXPECT_EQ(dof.row, u_rows + k);  // appended in creation order
    EXPECT_EQ(box.body.find_enriched_dof(dof.vertex, dof.cut_id, dof.side), k);
    if (box.body.dofs().vertex_row[static_cast<size_t>(dof.vertex)] < 0) ++fixed_enriched;
  }
  EXPECT_EQ(fixed_enriched, 9);  // the 3x3 vertices of the fixed face, all below the cut
  for (const CutTet& cut_tet : box.body.cut_tets()) {
    for (size_t i = 0; i < 4; ++i) {
      const int k = box.body.find_enriched_dof(cut_tet.vertices[i], 0, cut_tet.cut.side[i]);
      EXPECT_EQ(cut_tet.enriched_row[i], u_rows + k);
    }
    EXPECT_TRUE(box.body.elasticity().is_excluded(cut_tet.cut.tet));
  }

  // A second cut (another id) through a tet of the next cube, sharing enriched vertices at
  // x = 0.01, makes new unknowns for all four of its vertices.
  const int before = box.body.enriched_dof_count();
  std::optional<TetCut> second;
  for (int t = 5; t < 10 && !second; ++t)
    second = xfem_test::plane_tet_cut(box.mesh, t, Plane{Eigen::Vector3d::UnitY(), 0.0051}, 1);
  ASSERT_TRUE(second.has_value());
  int shared = 0;
  for (int v : box.mesh.tets[static_cast<size_t>(second->tet)])
    shared += box.body.find_enriched_dof(v, 0, -1) >= 0 || box.body.find_enriched_dof(v, 0, 1) >= 0;
  EXPECT_GT(shared, 0);
  box.body.enrich(*second);
  EXPECT_EQ(box.body.enriched_dof_count(), before + 4);
}

TEST(XfemEnrich, EnrichedMassIsTheMassAcrossTheCutAndTotalMassIsKept) {
  // The ghost of vertex i: sum over its cut tets of rho V_across(i) / 4 (the part across the cut
  // uses the ghost), V_across from the clipped geometry (computed here from the plane, independently
  // of the fractions handed over), and that mass's weight. The same mass and weight leave u_i:
  // each vertex's copies carry what it carried.
  Box box;
  const Plane plane{Eigen::Vector3d(1, 0.3, -0.2).normalized(), 0.0222};
  const Eigen::VectorXd mass_before = box.body.mass_kg();
  const Eigen::VectorXd force_before = box.body.external_force_n();
  const double total_before = box.body.total_mass_kg();
  box.body.enrich(xfem_test::plane_cuts(box.mesh, plane));

  const int u_rows = box.body.dofs().free_vertex_count();
  std::map<int, double> expected_mass;  // by enriched row
  for (const CutTet& cut_tet : box.body.cut_tets()) {
    const TetPositions x = xfem_test::tet_positions(box.mesh, cut_tet.cut.tet);
    const double volume = signed_tet_volume(x[0], x[1], x[2], x[3]);
    const double above = xfem_test::clipped_volume_fraction_above(x, plane) * volume;
    for (size_t i = 0; i < 4; ++i) {
      expected_mass[cut_tet.enriched_row[i]] += 1000.0 * (cut_tet.cut.side[i] == 1 ? volume - above : above) / 4.0;
    }
  }
  ASSERT_EQ(static_cast<int>(expected_mass.size()), box.body.enriched_dof_count());
  Eigen::VectorXd mass_of_copies = box.body.mass_kg().head(3 * u_rows);
  Eigen::VectorXd force_of_copies = box.body.external_force_n().head(3 * u_rows);
  for (const auto& [row, mass] : expected_mass) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(box.body.mass_kg()(3 * row + c), mass, 1e-12 * mass);
    EXPECT_NEAR(box.body.external_force_n()(3 * row + 2), mass * -9.81, 1e-12 * mass * 9.81);
    EXPECT_EQ(box.body.external_force_n()(3 * row), 0.0);
    const int vertex_row =
        box.body.dofs().vertex_row[static_cast<size_t>(box.body.enriched_dofs()[static_cast<size_t>(row - u_rows)].vertex)];
    if (vertex_row < 0) continue;  // a fixed vertex's ghost
    mass_of_copies.segment<3>(3 * vertex_row) += box.body.mass_kg().segment<3>(3 * row);
    force_of_copies.segment<3>(3 * vertex_row) += box.body.external_force_n().segment<3>(3 * row);
  }
  EXPECT_LT((mass_of_copies - mass_before).norm(), 1e-15);
  EXPECT_LT((force_of_copies - force_before).norm(), 1e-14);
  EXPECT_EQ(box.body.total_mass_kg(), total_before);
  EXPECT_NEAR(total_before, 1000.0 * 4 * 2 * 2 * 1e-6, 1e-12);

  // The parts of each cut tet share its mass out exactly.
  for (int k = 0; k < static_cast<int>(box.body.cut_tets().size()); ++k) {
    const TetRest& rest = box.body.xfem().rest(k);
    EXPECT_NEAR(box.body.part_mass_kg(k, CutPart::above) + box.body.part_mass_kg(k, CutPart::below),
                1000.0 * rest.volume_m3, 1e-15);
  }
}

TEST(XfemEnrich, RefusesBadCutsAndChangesNothing) {
  Box box;
  TetCut good;
  good.tet = 7;
  good.side = {1, -1, 1, 1};
  good.volume_fraction_above = 0.4;
  const auto refused = [&](const std::vector<TetCut>& cuts) {
    const int dofs = box.body.dof_count();
    const auto pattern = box.body.tangent().pattern_revision();
    EXPECT_THROW(box.body.enrich(cuts), ParameterError);
    EXPECT_EQ(box.body.dof_count(), dofs);
    EXPECT_EQ(box.body.tangent().pattern_revision(), pattern);
    EXPECT_EQ(box.body.cut_tets().size(), 0u);
  };
  auto bad = good;
  bad.tet = -1;
  refused({good, bad});
  bad.tet = box.mesh.tet_count();
  refused({good, bad});
  bad = good;
  bad.side = {1, 1, 1, 1};
  refused({good, bad});
  bad.side = {1, 0, -1, 1};
  refused({good, bad});
  bad = good;
  for (double fraction : {0.0, 1.0, -0.1, std::nan(""), std::numeric_limits<double>::infinity()}) {
    bad.volume_fraction_above = fraction;
    refused({good, bad});
  }
  // Found by fuzzing the FMU's state (issue 44): a part under the floor SMALLEST_MIN_VOLUME_FRACTION
  // (at 5e-324 a ghost had no mass and no stiffness and the solve refused the system), a smallest
  // fraction under the floor, a crossing off its edge, a blade normal not finite.
  for (double fraction : {5e-324, 1e-13, 1.0 - 1e-13}) {
    bad.volume_fraction_above = fraction;
    refused({good, bad});
  }
  bad = good;
  bad.min_volume_fraction = 1e-300;
  bad.volume_fraction_above = 1e-300;
  refused({good, bad});
  bad = good;
  bad.edge_ratio[2] = 1.5;
  refused({good, bad});
  bad.edge_ratio[2] = std::nan("");
  refused({good, bad});
  bad = good;
  bad.blade_normal.x() = std::numeric_limits<double>::infinity();
  refused({good, bad});
  bad = good;
  bad.volume_fraction_above = 1e-4;  // under the cutter's clamp, over the floor (an exact cut in code): taken
  EXPECT_NO_THROW(Box{}.body.enrich(bad));
  refused({good, good});  // the same tet twice

  box.body.enrich(good);
  EXPECT_EQ(box.body.cut_tets().size(), 1u);
  EXPECT_THROW(box.body.enrich(good), ParameterError);  // one cut per tet
  EXPECT_EQ(box.body.cut_tets().size(), 1u);

  DynamicState too_long{Eigen::VectorXd::Zero(box.body.dof_count() + 3),
                        Eigen::VectorXd::Zero(box.body.dof_count() + 3)};
  EXPECT_THROW(box.body.grow_state(too_long), std::invalid_argument);
  Eigen::VectorXd f;
  EXPECT_THROW(box.body.evaluate(Eigen::VectorXd::Zero(3), f, false), std::invalid_argument);
}

}  // namespace
}  // namespace tissue
