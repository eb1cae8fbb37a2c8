// End-to-end cutting through the Tissue facade (dissertation figures 6.5-6.9): a scalpel swept
// across a cantilever beam, through the surface BVH, the volume cutter and the XFEM growth.
// * A complete cut: the free piece's translational momentum c^T M v obeys the damped free-fall
//   law exactly (c^T f_int = 0 for a detached piece, c^T f_ext = M_free g; see
//   tests/physics/test_free_fall.cpp), the clamped piece stays, mass and tets unchanged.
// * A partial cut leaves the piece attached; two and three separate cuts each separate a piece.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"
#include "support/scalpel_stroke.hpp"
#include "unit/fem/body_pieces.hpp"

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace tissue {
namespace {

constexpr double LENGTH_M = 0.1;
constexpr double SIDE_M = 0.02;
constexpr double GRAVITY = 9.81;
constexpr double ALPHA_PER_S = 1.0;
constexpr double STEP_S = 1e-3;
constexpr double DENSITY = 1000.0;

TissueSettings beam_settings(const TetMesh& mesh) {
  TissueSettings settings;
  settings.body.material = Material{5.0e5, 0.3, DENSITY};
  settings.body.damping = RayleighDamping{ALPHA_PER_S, 1e-3};
  settings.body.gravity_m_per_s2 = {0.0, 0.0, -GRAVITY};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.solver.kind = LinearSolverKind::cholmod;
  settings.step_size_s = STEP_S;
  settings.interaction.blade_length_m = 0.06;
  return settings;
}

// A vertical scalpel at x = cut_x, swept along y from y_from to y_to at 0.2 m/s, then put away.
void sweep(Tissue& tissue, double cut_x, double y_from, double y_to) {
  test_support::draw_scalpel(tissue, {cut_x, y_from}, {cut_x, y_to}, STEP_S, [] {});
}

double mean_z_displacement(const Tissue& tissue, double x_min, double x_max) {
  const TetMesh& mesh = tissue.body().mesh();
  const Eigen::VectorXd& x = tissue.current_positions_m();
  double sum = 0.0;
  int count = 0;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const double rest_x = mesh.rest_positions_m[static_cast<size_t>(v)].x();
    if (rest_x < x_min || rest_x > x_max) continue;
    sum += x(3 * v + 2) - mesh.rest_positions_m[static_cast<size_t>(v)].z();
    ++count;
  }
  return sum / count;
}

// The z drop of an ideal damped free fall after `steps` backward-Euler steps from rest.
double free_fall_drop_m(int steps) {
  double velocity = 0.0;
  double drop = 0.0;
  for (int n = 0; n < steps; ++n) {
    velocity = (velocity - STEP_S * GRAVITY) / (1.0 + STEP_S * ALPHA_PER_S);
    drop += STEP_S * velocity;
  }
  return drop;
}

// The longest edge [m] of the triangles, at the current positions.
double longest_edge_m(const Eigen::VectorXd& x, const std::vector<std::array<int, 3>>& triangles) {
  double longest = 0.0;
  for (const auto& t : triangles) {
    for (int c = 0; c < 3; ++c) {
      const int a = t[static_cast<size_t>(c)], b = t[static_cast<size_t>((c + 1) % 3)];
      longest = std::max(longest, (x.segment<3>(3 * a) - x.segment<3>(3 * b)).norm());
    }
  }
  return longest;
}

// The surface output after a complete cut (tissue_fmu: the mesh's surface without the replaced
// triangles, the skin pieces, the cut faces): once the free piece has fallen 2 cm, no output
// triangle spans the opening. The replaced originals would (that is the defect the skin fixes).
TEST(ScalpelCut, NoSurfaceTriangleStretchesAcrossTheOpening) {
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue tissue(mesh, beam_settings(mesh));
  sweep(tissue, 0.0553, -0.005, 0.025);
  const double tip_before = mean_z_displacement(tissue, 0.09, 0.1);
  while (mean_z_displacement(tissue, 0.09, 0.1) - tip_before > -0.02) tissue.step();
  ASSERT_GT(tissue.drawn_triangle_count(), 0u);  // the drawn lists below are made when the surface is read
  const CutSurface& cuts = tissue.cut_surface();
  const auto& mesh_triangles = tissue.surface().triangles;
  // The cut layer's outside: 4 sides of 2 squares of 1 cm, 2 triangles each.
  ASSERT_EQ(cuts.replaced_triangles().size(), 16u);
  std::vector<std::array<int, 3>> output, replaced;
  for (size_t t = 0; t < mesh_triangles.size(); ++t) {
    const bool is_replaced =
        std::binary_search(cuts.replaced_triangles().begin(), cuts.replaced_triangles().end(), static_cast<int>(t));
    (is_replaced ? replaced : output).push_back(mesh_triangles[t]);
  }
  output.insert(output.end(), cuts.skin_triangles().begin(), cuts.skin_triangles().end());
  output.insert(output.end(), cuts.triangles().begin(), cuts.triangles().end());
  const Eigen::VectorXd& x = tissue.current_positions_m();
  // A face diagonal of a 1 cm cube is 1.41 cm; the skin's pieces are parts of such triangles and
  // the beam's strain is small, so nothing longer than 1.5 cm may appear.
  EXPECT_LT(longest_edge_m(x, output), 0.015);
  EXPECT_GT(longest_edge_m(x, replaced), 0.02);
  // The pieces cover the replaced triangles: 16 half squares of 1 cm^2, up to the small strain.
  double skin_area = 0.0;
  for (const auto& t : cuts.skin_triangles()) {
    skin_area +=
        0.5 *
        (x.segment<3>(3 * t[1]) - x.segment<3>(3 * t[0])).cross(x.segment<3>(3 * t[2]) - x.segment<3>(3 * t[0])).norm();
  }
  const double replaced_area = 16 * 0.5e-4;
  EXPECT_NEAR(skin_area, replaced_area, 0.05 * replaced_area);
}

TEST(ScalpelCut, CompleteCutReleasesTheFreePieceIntoFreeFall) {
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  const int tets = mesh.tet_count();
  Tissue tissue(mesh, beam_settings(mesh));
  const double mass_before = tissue.body().total_mass_kg();
  constexpr double CUT_X = 0.0553;
  sweep(tissue, CUT_X, -0.005, 0.025);
  EXPECT_FALSE(tissue.cutter().cutting());  // the blade left the body: the session ended

  // Every tet of the 6th layer (the plane x = CUT_X crosses all 4 x 5 of them) and no other.
  const auto& cut_tets = tissue.body().cut_tets();
  ASSERT_EQ(cut_tets.size(), 20u);
  for (int t = 0; t < tets; ++t) {
    double lo = 1.0, hi = -1.0;
    for (int v : mesh.tets[static_cast<size_t>(t)]) {
      lo = std::min(lo, mesh.rest_positions_m[static_cast<size_t>(v)].x());
      hi = std::max(hi, mesh.rest_positions_m[static_cast<size_t>(v)].x());
    }
    EXPECT_EQ(tissue.body().cut_tet_index(t) >= 0, lo < CUT_X && CUT_X < hi) << "tet " << t;
  }
  EXPECT_EQ(tissue.body().mesh().tet_count(), tets);
  EXPECT_DOUBLE_EQ(tissue.body().total_mass_kg(), mass_before);

  // Two bodies now: the clamped piece and the free one (x > CUT_X), which its rows alone move (real
  // vertices and ghosts are copies with displacements of their own). The blade cut the sagging
  // beam, so the material cut surface is only near x = CUT_X.
  const DeformableBody& body = tissue.body();
  const std::vector<xfem_test::BodyPiece> pieces = xfem_test::body_pieces(body);
  ASSERT_EQ(pieces.size(), 2u);
  const xfem_test::BodyPiece& free_piece = pieces[0].held ? pieces[1] : pieces[0];
  ASSERT_FALSE(free_piece.held);
  const double free_mass = free_piece.mass_kg;
  const Eigen::VectorXd c_z = xfem_test::translation(body, free_piece, 2);
  EXPECT_NEAR(free_mass, DENSITY * (LENGTH_M - CUT_X) * SIDE_M * SIDE_M, 0.01 * free_mass);
  // Its lumped mass is its mass, and its load its weight.
  EXPECT_NEAR(c_z.dot(body.mass_kg()), free_mass, 1e-12 * free_mass);
  ASSERT_NEAR(c_z.dot(body.external_force_n()), -free_mass * GRAVITY, 1e-12);

  // Backward Euler on the detached piece: Pi_{n+1} = (Pi_n - h M_free g) / (1 + h alpha), exactly.
  double momentum = c_z.dot(body.mass_kg().cwiseProduct(tissue.state().velocity_m_per_s));
  double worst_error = 0.0;
  const double clamp_before = mean_z_displacement(tissue, 0.0, 0.02);
  const double tip_before = mean_z_displacement(tissue, 0.09, 0.1);
  const int steps = 200;
  for (int n = 0; n < steps; ++n) {
    tissue.step();
    momentum = (momentum - STEP_S * free_mass * GRAVITY) / (1.0 + STEP_S * ALPHA_PER_S);
    const double measured = c_z.dot(tissue.body().mass_kg().cwiseProduct(tissue.state().velocity_m_per_s));
    worst_error = std::max(worst_error, std::abs(measured - momentum) / (free_mass * GRAVITY * STEP_S * steps));
  }
  ASSERT_TRUE(tissue.state().displacement_m.allFinite());
  // Round-off of CHOLMOD solves over 200 steps; the law itself is exact.
  EXPECT_LT(worst_error, 1e-8);
  // The tip falls with the piece: the ideal drop, up to the piece's turn about its centre and its
  // elastic wobble (a few millimetres against 0.18 m).
  const double drop = mean_z_displacement(tissue, 0.09, 0.1) - tip_before;
  const double ideal = free_fall_drop_m(steps);
  EXPECT_GT(drop / ideal, 0.95);
  EXPECT_LT(drop, ideal * 1.0 + 1e-3);
  // The opened faces: one per piece, each of the beam's cross-section area (0.02 x 0.02 m, to the
  // strain), facing outward: +x on the clamped piece (tilted by its sag); the falling piece tumbles
  // (it pivoted on its last connection), so only its face's area is checked.
  const Eigen::VectorXd& x = tissue.current_positions_m();
  Eigen::Vector3d falling_face = Eigen::Vector3d::Zero();
  Eigen::Vector3d clamped_face = Eigen::Vector3d::Zero();
  for (const auto& t : tissue.cut_surface().triangles()) {
    const Eigen::Vector3d a = x.segment<3>(3 * t[0]), b = x.segment<3>(3 * t[1]), c = x.segment<3>(3 * t[2]);
    (a.z() < -0.05 ? falling_face : clamped_face) += 0.5 * (b - a).cross(c - a);
  }
  const double section_m2 = SIDE_M * SIDE_M;
  EXPECT_NEAR(falling_face.norm(), section_m2, 0.03 * section_m2);
  EXPECT_NEAR(clamped_face.norm(), section_m2, 0.03 * section_m2);
  EXPECT_GT(clamped_face.x(), 0.99 * clamped_face.norm());
  EXPECT_EQ(tissue.surface_bvh().triangle_count(),
            static_cast<int>(tissue.surface().triangles.size() + tissue.cut_surface().triangles().size()));

  // The clamped end barely moves (millimetre-scale sag against a 0.18 m fall).
  EXPECT_LT(std::abs(mean_z_displacement(tissue, 0.0, 0.02) - clamp_before), 1e-3);
}

TEST(ScalpelCut, PartialCutLeavesThePieceAttached) {
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue tissue(mesh, beam_settings(mesh));
  // Stops in the first row of cubes (5.3 mm into the 0.02 m width): when the scalpel is taken away
  // the stroke ends at the far faces of the tets the blade went into, and the second row holds on.
  sweep(tissue, 0.0553, -0.005, 0.0053);
  EXPECT_GT(tissue.body().cut_tets().size(), 0u);
  EXPECT_LT(tissue.body().cut_tets().size(), 20u);
  for (int n = 0; n < 200; ++n) tissue.step();
  ASSERT_TRUE(tissue.state().displacement_m.allFinite());
  // Free fall would be 0.18 m; the attached cantilever sags a few millimetres.
  EXPECT_GT(mean_z_displacement(tissue, 0.09, 0.1), -0.01);
}

// The Jacobi-scaled condition number of A = M / h^2 + K (the backward-Euler matrix without damping).
double scaled_condition_number(const Tissue& tissue) {
  const BlockSparseMatrix& k = tissue.body().tangent();
  const Eigen::Index n = tissue.body().dof_count();
  Eigen::MatrixXd a(n, n);
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(n), column(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    unit(j) = 1.0;
    k.multiply(unit, column);
    a.col(j) = column;
    unit(j) = 0.0;
  }
  a.diagonal() += tissue.body().mass_kg() / (STEP_S * STEP_S);
  const Eigen::VectorXd scale = a.diagonal().cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * a * scale.asDiagonal();
  const Eigen::VectorXd eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues();
  return eigenvalues.maxCoeff() / eigenvalues.minCoeff();
}

// A cut exactly along grid faces, through vertices and edges, of an unstressed beam (no gravity,
// so it stays exactly at rest): every cut tet has one part of the smallest allowed volume fraction.
// Both mass and stiffness of a part scale with its volume fraction, so after Jacobi scaling the
// system is no worse conditioned than for an ordinary cut, whatever that fraction: the condition
// number with eps = 1e-6 matches the one with eps = 1e-3 (to 1%), CHOLMOD factorizes every step,
// the unstressed body feels no force from the cut and the mass is kept.
TEST(ScalpelCut, CutAlongGridFacesStaysSolvableForAnySmallestVolumeFraction) {
  std::vector<double> conditions;
  for (const double eps : {1e-3, 1e-6}) {
    TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
    TissueSettings settings = beam_settings(mesh);
    settings.body.gravity_m_per_s2.setZero();
    settings.interaction.cutter.min_volume_fraction = eps;
    Tissue tissue(mesh, settings);
    const double mass = tissue.body().total_mass_kg();
    sweep(tissue, 0.05, -0.00513, 0.02487);  // x = 0.05 is a grid plane: vertices, edges and faces
    ASSERT_GT(tissue.body().cut_tets().size(), 0u);
    for (const CutTet& cut : tissue.body().cut_tets()) {
      const double above = cut.cut.volume_fraction_above;
      EXPECT_TRUE(above == eps || above == 1.0 - eps) << above;
    }
    EXPECT_NEAR(tissue.body().total_mass_kg(), mass, 1e-12 * mass);
    for (int n = 0; n < 20; ++n) tissue.step();  // throws IntegrationError if CHOLMOD fails
    // Round-off only: the rest-state strain of 0.01 m elements is ~1e-16, displacements ~1e-17 m.
    EXPECT_LT(tissue.state().displacement_m.lpNorm<Eigen::Infinity>(), 1e-14);
    conditions.push_back(scaled_condition_number(tissue));
  }
  std::printf("  scaled condition number: eps 1e-3 %.6g, eps 1e-6 %.6g\n", conditions[0], conditions[1]);
  EXPECT_NEAR(conditions[1] / conditions[0], 1.0, 0.01);
}

// The surface's positions are written when first read after a step (SurfaceViews), and a cut
// body's update skips the corners of retired faces (CutSurface::update_points' runs). A tissue read
// after every step and one read only at the end hold the same positions, bitwise; the first's mesh
// vertices are those of the step just taken at every read (never the step before); and a fresh
// instance that replays the cuts (every corner written by the full pass) agrees with both.
TEST(ScalpelCut, PositionsWrittenWhenReadAreThoseOfTheLastStepWhoeverReads) {
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue every_step(mesh, beam_settings(mesh));
  Tissue at_end(mesh, beam_settings(mesh));
  int stale_reads = 0, reads = 0;
  Eigen::VectorXd vertices_m;
  const auto read = [&] {
    const Eigen::VectorXd& x = every_step.current_positions_m();
    (void)every_step.surface_bvh();  // the refit reads them too
    every_step.vertex_positions(vertices_m);
    ++reads;
    if (x.head(vertices_m.size()) != vertices_m) ++stale_reads;
  };
  // An X through the beam seen from above (two slanted strokes past both sides, crossing at
  // x = 5 cm): the tets both cross retire their first cut's faces.
  for (Tissue* tissue : {&every_step, &at_end}) {
    const auto after_step = [&, reading = tissue == &every_step] {
      if (reading) read();
    };
    test_support::draw_scalpel(*tissue, {0.0443, -0.005}, {0.0623, 0.025}, STEP_S, after_step);
    test_support::draw_scalpel(*tissue, {0.0563, -0.005}, {0.0383, 0.025}, STEP_S, after_step);
    for (int n = 0; n < 20; ++n) {
      tissue->step();
      after_step();
    }
  }
  EXPECT_EQ(stale_reads, 0) << "of " << reads;
  int retired = 0;
  for (int k = 0; k < every_step.body().cut_tet_count(); ++k) retired += every_step.body().retired(k) ? 1 : 0;
  EXPECT_GT(retired, 0);
  ASSERT_TRUE(every_step.current_positions_m().allFinite());
  EXPECT_EQ(every_step.current_positions_m(), at_end.current_positions_m());
  TissueSnapshot snapshot;
  at_end.save(snapshot);
  std::unique_ptr<Tissue> replayed = std::make_unique<Tissue>(mesh, beam_settings(mesh));
  restore_or_replay(replayed, snapshot);
  EXPECT_EQ(replayed->current_positions_m(), at_end.current_positions_m());
}

class SeparateCuts : public ::testing::TestWithParam<std::vector<double>> {};

TEST_P(SeparateCuts, EachCutReleasesItsPiece) {
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue tissue(mesh, beam_settings(mesh));
  const std::vector<double>& cuts = GetParam();
  // From the tip inward, so that each sweep cuts the part still attached (a released piece falls away).
  for (auto x = cuts.rbegin(); x != cuts.rend(); ++x) sweep(tissue, *x, -0.005, 0.025);
  EXPECT_EQ(tissue.body().cut_tets().size(), 20u * cuts.size());
  EXPECT_EQ(tissue.cutter().cut_id(), static_cast<int>(cuts.size()) - 1);  // one session per cut
  for (int n = 0; n < 200; ++n) tissue.step();
  ASSERT_TRUE(tissue.state().displacement_m.allFinite());
  // Every piece beyond the first cut falls (> 0.85 of the ideal drop, as above); the clamped one stays.
  const double ideal = free_fall_drop_m(200);
  for (size_t k = 0; k < cuts.size(); ++k) {
    const double piece_end = k + 1 < cuts.size() ? cuts[k + 1] : LENGTH_M;
    EXPECT_GT(mean_z_displacement(tissue, cuts[k] + 1e-3, piece_end) / ideal, 0.8) << "piece after cut " << k;
  }
  EXPECT_LT(mean_z_displacement(tissue, 0.0, 0.01), 1e-3);
}

INSTANTIATE_TEST_SUITE_P(TwoAndThree, SeparateCuts,
                         ::testing::Values(std::vector<double>{0.0353, 0.0753},
                                           std::vector<double>{0.0253, 0.0553, 0.0853}));

}  // namespace
}  // namespace tissue
