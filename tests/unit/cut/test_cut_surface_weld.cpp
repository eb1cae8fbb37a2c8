// The drawn tet skin is welded (issue 43): after a scalpel's cut the surface a viewer gets
// (Tissue::for_each_drawn_triangle over current_positions_m) is a closed, consistently oriented
// 2-manifold per piece: every edge, counted by its pair of point ids, has exactly two triangles, one
// each way. A complete cut makes two such surfaces that share no point (the sides move apart); a cut
// the blade stops inside leaves one, joined beyond the crack's front.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "core/tissue_settings_schema.hpp"
#include "core/tissue.hpp"
#include "support/closed_surface.hpp"
#include "support/scalpel_stroke.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <array>
#include <filesystem>
#include <functional>
#include <vector>

namespace tissue {
namespace {

using test_support::SurfaceCheck;

constexpr double STEP_S = 1e-3;

TissueSettings beam_settings(const TetMesh& mesh) {
  TissueSettings settings;
  settings.body.material = Material{5.0e5, 0.3, 1000.0};
  settings.body.damping = RayleighDamping{1.0, 1e-3};
  settings.body.gravity_m_per_s2 = {0.0, 0.0, -9.81};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.solver.kind = LinearSolverKind::cholmod;
  settings.step_size_s = STEP_S;
  settings.interaction.blade_length_m = 0.06;
  return settings;
}

// A vertical scalpel at x = cut_x drawn along y from y_from to y_to at 0.2 m/s, then put away.
void sweep(Tissue& tissue, double cut_x, double y_from, double y_to) {
  test_support::draw_scalpel(tissue, {cut_x, y_from}, {cut_x, y_to}, STEP_S, [] {});
}

// The drawn surface over current_positions_m, as a viewer gets it.
SurfaceCheck check_drawn_surface(const Tissue& tissue) {
  std::vector<std::array<int, 3>> triangles;
  tissue.for_each_drawn_triangle([&](const std::array<int, 3>& t) { triangles.push_back(t); });
  EXPECT_EQ(triangles.size(), tissue.drawn_triangle_count());
  const auto points = static_cast<int>(tissue.current_positions_m().size() / 3);
  for (const auto& t : triangles) {
    for (const int point : t) {
      EXPECT_LT(point, points);
      if (point >= points) return {};  // failed: not a surface over these points
    }
  }
  return test_support::check_surface(triangles, points);
}

// A stroke from (x, y) `from` to `to` (then put away): the most open edges the drawn surface had after
// any step.
int stroke_worst_open(Tissue& tissue, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  int worst_open = 0;
  test_support::draw_scalpel(tissue, from, to, STEP_S,
                             [&] { worst_open = std::max(worst_open, check_drawn_surface(tissue).open_edges); });
  return worst_open;
}

TEST(CutSurfaceWeld, CompleteCutDrawsTwoClosedSurfacesSharingNoPoint) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue tissue(mesh, beam_settings(mesh));
  const SurfaceCheck uncut = check_drawn_surface(tissue);
  EXPECT_EQ(uncut.open_edges, 0);
  EXPECT_EQ(uncut.pieces, 1);
  sweep(tissue, 0.0553, -0.005, 0.025);
  ASSERT_EQ(tissue.body().cut_tets().size(), 20u);
  for (int n = 0; n < 50; ++n) tissue.step();  // the free end falls away
  const SurfaceCheck cut = check_drawn_surface(tissue);
  EXPECT_EQ(cut.open_edges, 0);
  EXPECT_EQ(cut.degenerate, 0);
  EXPECT_EQ(cut.pieces, 2);  // and so no point is in both
  EXPECT_TRUE(tissue.current_positions_m().allFinite());
}

TEST(CutSurfaceWeld, CutStoppedInsideStaysClosedAndJoined) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue tissue(mesh, beam_settings(mesh));
  sweep(tissue, 0.0553, -0.005, 0.0133);  // through two thirds of the 2 cm width
  ASSERT_GT(tissue.body().cut_tets().size(), 0u);
  ASSERT_LT(tissue.body().cut_tets().size(), 20u);
  for (int n = 0; n < 20; ++n) tissue.step();
  const SurfaceCheck cut = check_drawn_surface(tissue);
  EXPECT_EQ(cut.open_edges, 0);
  EXPECT_EQ(cut.degenerate, 0);
  EXPECT_EQ(cut.pieces, 1);
}

// The weld holds at every step of a stroke, while the crack's front moves through the body.
TEST(CutSurfaceWeld, ClosedAtEveryStepOfTheStroke) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue tissue(mesh, beam_settings(mesh));
  const int worst_open = stroke_worst_open(tissue, {0.0553, -0.005}, {0.0553, 0.025});
  EXPECT_EQ(tissue.body().cut_tets().size(), 20u);
  EXPECT_EQ(worst_open, 0);
}

// Cut through material the fixed region holds (issue 41): the clamped cubes' pieces take held copies of
// their fixed vertices, which the weld keeps apart from the real vertices as it keeps ghosts apart. A
// stroke along the whole beam through the 3 cm clamp draws two closed surfaces at every step (the
// halves share no material), and a stroke across inside the clamp one closed surface.
TEST(CutSurfaceWeld, CutsThroughHeldMaterialStayClosedAtEveryStep) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  TissueSettings settings = beam_settings(mesh);
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.3 + 1e-6);
  Tissue along(mesh, settings);
  EXPECT_EQ(stroke_worst_open(along, {-0.005, 0.0095}, {0.105, 0.0095}), 0);
  ASSERT_GT(along.body().held_copies().size(), 0u);
  for (int n = 0; n < 20; ++n) along.step();
  const SurfaceCheck halves = check_drawn_surface(along);
  EXPECT_EQ(halves.open_edges, 0);
  EXPECT_EQ(halves.degenerate, 0);
  EXPECT_EQ(halves.pieces, 2);
  Tissue across(mesh, settings);
  EXPECT_EQ(stroke_worst_open(across, {0.0153, -0.005}, {0.0153, 0.025}), 0);
  ASSERT_GT(across.body().held_copies().size(), 0u);
  const SurfaceCheck clamp = check_drawn_surface(across);
  EXPECT_EQ(clamp.open_edges, 0);
  EXPECT_EQ(clamp.degenerate, 0);
  EXPECT_EQ(clamp.pieces, 2);
}

TissueSettings block_settings(const TetMesh& mesh) {
  TissueSettings settings = beam_settings(mesh);
  settings.body.gravity_m_per_s2 = {0.0, 0.0, 0.0};
  return settings;
}

// Tets cut by two strokes (issue 21), a flap's corner: a 4 x 4 x 2 cm block cut through along
// x = 2.53 cm, then a second stroke run in from the side to just short of the first cut. Its crack's
// front ends in tets the first stroke cut: the surface triangles there, skin pieces of those tets, are
// drawn split where the second crack opens to the surface (before: 8 open edges).
TEST(CutSurfaceWeld, StrokeStoppingShortOfAnotherCutStaysClosedAtEveryStep) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  Tissue tissue(mesh, block_settings(mesh));
  EXPECT_EQ(stroke_worst_open(tissue, {0.0253, -0.005}, {0.0253, 0.045}), 0);
  const std::size_t once = tissue.body().cut_tets().size();
  EXPECT_EQ(stroke_worst_open(tissue, {0.045, 0.0207}, {0.0305, 0.0207}), 0);
  ASSERT_GT(tissue.body().cut_tets().size(), once);
  const SurfaceCheck cut = check_drawn_surface(tissue);
  EXPECT_EQ(cut.degenerate, 0);
  EXPECT_EQ(cut.pieces, 2);  // the second crack does not part the far side
}

// A T junction as a hand makes it: the second stroke runs through the first cut and a little past
// it, so its front lies in tets the first cut, some of them cut by both (before: 8 open edges).
TEST(CutSurfaceWeld, StrokeRunningPastAnotherCutStaysClosedAtEveryStep) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  Tissue tissue(mesh, block_settings(mesh));
  EXPECT_EQ(stroke_worst_open(tissue, {0.0253, -0.005}, {0.0253, 0.045}), 0);
  const std::size_t once = tissue.body().cut_tets().size();
  EXPECT_EQ(stroke_worst_open(tissue, {0.045, 0.0137}, {0.0212, 0.0137}), 0);
  ASSERT_GT(tissue.body().cut_tets().size(), once);
  const SurfaceCheck cut = check_drawn_surface(tissue);
  EXPECT_EQ(cut.degenerate, 0);
  EXPECT_EQ(cut.pieces, 3);  // the first cut's far side parted, its near side cracked
}

// A T junction whose front crosses mesh edges the first cut crosses too: the second stroke stops
// 0.6 mm past the first cut, in tets the first cut cut. Its corners there in the tets cut twice see
// the vertex beyond the second cut through a ghost the neighbours cut once do not use; the rows kept
// to the cuts both tets have agree, so they are one point (before: 8 open edges).
TEST(CutSurfaceWeld, StrokeEndingJustPastAnotherCutStaysClosedAtEveryStep) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  Tissue tissue(mesh, block_settings(mesh));
  EXPECT_EQ(stroke_worst_open(tissue, {0.0253, -0.005}, {0.0253, 0.045}), 0);
  EXPECT_EQ(stroke_worst_open(tissue, {0.045, 0.0137}, {0.0247, 0.0137}), 0);
  EXPECT_EQ(check_drawn_surface(tissue).degenerate, 0);
}

// What the weld joins is joined in the material: an X through a block held at both ends, whose top
// and bottom quarters then fall 0.1 m, is drawn as four pieces and no drawn edge is longer than a
// tet's (a corner welded across the cut would stretch a triangle from a held piece to a fallen one).
TissueSettings x_cut_settings(const TetMesh& mesh) {
  TissueSettings settings = beam_settings(mesh);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<size_t>(v)].x() > 0.04 - 1e-9) settings.body.fixed_vertices.push_back(v);
  }
  return settings;
}

// The two strokes of the X, then 150 steps; `after_step` after each step.
void cut_x_and_let_fall(Tissue& tissue, const std::function<void()>& after_step) {
  test_support::draw_scalpel(tissue, {0.0033, -0.005}, {0.0347, 0.045}, STEP_S, after_step);
  test_support::draw_scalpel(tissue, {0.0374, -0.005}, {0.0060, 0.045}, STEP_S, after_step);
  for (int n = 0; n < 150; ++n) {
    tissue.step();
    after_step();
  }
}

std::vector<std::array<int, 3>> drawn_triangles(const Tissue& tissue) {
  std::vector<std::array<int, 3>> triangles;
  tissue.for_each_drawn_triangle([&](const std::array<int, 3>& t) { triangles.push_back(t); });
  return triangles;
}

// The drawn triangles by their corners' positions, each from its least corner on (winding kept),
// sorted.
std::vector<std::array<double, 9>> placed_triangles(const Tissue& tissue) {
  const Eigen::VectorXd& x = tissue.current_positions_m();
  std::vector<std::array<double, 9>> placed;
  for (const auto& t : drawn_triangles(tissue)) {
    std::array<std::array<double, 3>, 3> corners;
    for (size_t c = 0; c < 3; ++c) corners[c] = {x(3 * t[c]), x(3 * t[c] + 1), x(3 * t[c] + 2)};
    std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
    std::array<double, 9> flat;
    for (size_t c = 0; c < 3; ++c) std::copy(corners[c].begin(), corners[c].end(), flat.begin() + 3 * c);
    placed.push_back(flat);
  }
  std::sort(placed.begin(), placed.end());
  return placed;
}

TEST(CutSurfaceWeld, AnXCutThatFallsApartDrawsFourPiecesAndStretchesNothing) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  Tissue tissue(mesh, x_cut_settings(mesh));
  cut_x_and_let_fall(tissue, [] {});
  const std::vector<std::array<int, 3>> triangles = drawn_triangles(tissue);
  const Eigen::VectorXd& x = tissue.current_positions_m();
  double lowest_m = 0.0;
  for (Eigen::Index i = 2; i < x.size(); i += 3) lowest_m = std::min(lowest_m, x(i));
  ASSERT_LT(lowest_m, -0.05);  // the free quarters fell
  double longest_m = 0.0;
  for (const auto& t : triangles) {
    for (size_t c = 0; c < 3; ++c) {
      longest_m = std::max(longest_m, (x.segment<3>(3 * t[c]) - x.segment<3>(3 * t[(c + 1) % 3])).norm());
    }
  }
  EXPECT_LT(longest_m, 0.01 * std::sqrt(3.0) * 1.05);  // a cube's diagonal, 5% strain
  EXPECT_EQ(check_drawn_surface(tissue).pieces, 4);
}

// The drawn lists are made when the drawn surface is read, not by the steps (a scene that draws its
// render surface paid up to 0.5 ms a cutting step for a tet skin nobody drew: flap_frog), and a
// reader at the end gets what a reader after every step gets: the X above, read once at the end,
// against the same tissue read after every step (the welds' joins let go as the quarters fall).
TEST(CutSurfaceWeld, DrawnListsAreMadeWhenReadAsAReaderAfterEveryStepSeesThem) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  Tissue read_each_step(mesh, x_cut_settings(mesh)), read_at_end(mesh, x_cut_settings(mesh));
  cut_x_and_let_fall(read_each_step, [&] { EXPECT_GT(read_each_step.drawn_triangle_count(), 0u); });
  cut_x_and_let_fall(read_at_end, [] {});
  ASSERT_GT(read_at_end.body().cut_tets().size(), 0u);
  EXPECT_EQ(read_at_end.cut_surface().drawn_rebuilds(), 0);
  EXPECT_GT(read_each_step.cut_surface().drawn_rebuilds(), 1);
  // The same triangles at the same places (the points' numbers differ: a reader during the stroke
  // made points for the crack's front that a reader at the end does not need).
  EXPECT_EQ(placed_triangles(read_at_end), placed_triangles(read_each_step));
  EXPECT_LE(read_at_end.cut_surface().drawn_rebuilds(), 2);  // the cuts' lists; again for the joins let go
}

// The longest edge of `triangles` over current_positions_m. [m]
template <class Triangles>
double longest_edge_m(const Tissue& tissue, const Triangles& triangles) {
  const Eigen::VectorXd& x = tissue.current_positions_m();
  double longest = 0.0;
  for (const auto& t : triangles) {
    for (size_t c = 0; c < 3; ++c) {
      longest = std::max(longest, (x.segment<3>(3 * t[c]) - x.segment<3>(3 * t[(c + 1) % 3])).norm());
    }
  }
  return longest;
}

// Strokes closer than the tets, the frog sagging (docs/hatched_frog.toml's scene with 15 strokes
// across at its spacing; the first six): the drawn tet skin joins only points the material holds
// together. Its points drawn as one (welded corners of pieces with different rows, the two sides at
// a crack's front) are within WELD_APART_FRACTION of a tet's largest edge, so no drawn edge is longer
// than the pieces' own faces (the cut faces with their own corners) and the mesh's skin by more than
// a tet's largest edge. Before: after the sixth stroke a join and a front the later strokes made wrong
// drew a 58 mm edge, and sheets metres long as the pieces fell (15 + 15 strokes: 37 m).
TEST(CutSurfaceWeld, HatchedStrokesDrawNoSheetBetweenPiecesThatParted) {
  const TetMesh mesh = read_mesh(std::filesystem::path(TISSUE_MESH_DIR) / "frog.veg");
  TissueParameters parameters = default_parameters();
  set_value(*find_setting("fixedRegion.axis"), parameters, std::int64_t{2});
  set_value(*find_setting("fixedRegion.fraction"), parameters, 0.25);
  set_value(*find_setting("material.youngModulus"), parameters, 3e5);
  set_value(*find_setting("tool.bladeLength"), parameters, 0.2);
  set_value(*find_setting("stepSize"), parameters, 0.01);
  Tissue tissue(mesh, resolve_settings(parameters, &mesh));
  Eigen::Vector3d low = mesh.rest_positions_m.front(), high = low;
  double largest_tet_edge_m = 0.0;
  for (const Eigen::Vector3d& p : mesh.rest_positions_m) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  for (int t = 0; t < mesh.tet_count(); ++t) {
    largest_tet_edge_m = std::max(largest_tet_edge_m, largest_edge_m(mesh.rest_corners(t)));
  }
  const auto at = [&](double x, double y) {  // fractions of the rest box; the tip 2 heights below
    return Eigen::Vector3d(low.x() + x * (high.x() - low.x()), low.y() + y * (high.y() - low.y()),
                           low.z() - 2.0 * (high.z() - low.z()));
  };
  // Each stroke as the scenario's waypoints: put down below y = -0.15 at t0 + 0.05, drawn to y = 1.15
  // by t0 + 0.35, lifted at t0 + 0.40; 0.45 s apart. One step per 10 ms, the tool where the
  // waypoints put it (linear between them, the mode of the last one passed).
  constexpr int STROKES = 6;
  constexpr double PERIOD_S = 0.45;
  double worst_excess_m = -1.0;
  for (int n = 0; n <= static_cast<int>(STROKES * PERIOD_S / 0.01) + 30; ++n) {
    const double t = n * 0.01;
    const int k = std::min(STROKES - 1, static_cast<int>(t / PERIOD_S));
    const double x = 0.15 + 0.05 * k;
    const double local = t - k * PERIOD_S;
    const bool drawing = local >= 0.05 && local < 0.40;
    const double y = local < 0.05 ? -0.15 : local < 0.35 ? -0.15 + 1.3 * (local - 0.05) / 0.3 : 1.15;
    Eigen::Vector3d tool = at(x, y);
    if (local >= 0.40 && k + 1 < STROKES) {  // lifted, to the next stroke's start
      const double moved = (local - 0.40) / 0.05;
      tool = at(x + 0.05 * moved, 1.15 - 1.3 * moved);
    }
    tissue.set_tool(ToolPose{tool, Eigen::Quaterniond::Identity(), drawing ? ToolMode::scalpel : ToolMode::none});
    tissue.step();
    std::vector<std::array<int, 3>> drawn;
    tissue.for_each_drawn_triangle([&](const std::array<int, 3>& triangle) { drawn.push_back(triangle); });
    // The pieces' own faces: the cut faces with their own corners, and the mesh's skin triangles of
    // uncut tets.
    std::vector<std::array<int, 3>> own(tissue.cut_surface().triangles());
    const std::vector<int>& replaced = tissue.cut_surface().replaced_triangles();
    for (size_t s = 0; s < tissue.surface().triangles.size(); ++s) {
      if (std::binary_search(replaced.begin(), replaced.end(), static_cast<int>(s))) continue;
      own.push_back(tissue.surface().triangles[s]);
    }
    worst_excess_m = std::max(worst_excess_m, longest_edge_m(tissue, drawn) - longest_edge_m(tissue, own));
  }
  EXPECT_GT(tissue.body().cut_tets().size(), 500u);
  EXPECT_LE(worst_excess_m, largest_tet_edge_m);
}

// Two strokes crossing (an X) near a column of mesh vertices: the tets cut twice there each hold a
// sliver of a quadrant (the junction runs 0.35 mm from their face). A later cut now splits every
// piece it passes through, however thin (its fraction clamped to the smallest, as a first cut's is),
// so the tets either side of a face agree on its pieces; before, a piece it would have cut to less
// than the smallest fraction stayed whole in one tet and was cut in the next (24 open edges).
TEST(CutSurfaceWeld, CrossingStrokesStayClosedAtEveryStep) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  Tissue tissue(mesh, block_settings(mesh));
  EXPECT_EQ(stroke_worst_open(tissue, {0.0033, -0.005}, {0.0347, 0.045}), 0);
  EXPECT_EQ(stroke_worst_open(tissue, {0.0374, -0.005}, {0.0060, 0.045}), 0);
  EXPECT_EQ(check_drawn_surface(tissue).pieces, 4);
}

}  // namespace
}  // namespace tissue
