// The drawn tet skin is welded (issue 43): after a scalpel's cut the surface a viewer gets
// (Tissue::for_each_drawn_triangle over current_positions_m) is a closed, consistently oriented
// 2-manifold per piece: every edge, counted by its pair of point ids, has exactly two triangles, one
// each way. A complete cut makes two such surfaces that share no point (the sides move apart); a cut
// the blade stops inside leaves one, joined beyond the crack's front.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <set>
#include <utility>
#include <vector>

namespace tissue {
namespace {

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

// A vertical scalpel (tool axis +z) at x = cut_x drawn along y from y_from to y_to at 0.2 m/s, then
// put away.
void sweep(Tissue& tissue, double cut_x, double y_from, double y_to) {
  const int steps = static_cast<int>(std::ceil(std::abs(y_to - y_from) / (0.2 * STEP_S)));
  for (int n = 0; n <= steps; ++n) {
    const double y = y_from + (y_to - y_from) * n / steps;
    tissue.set_tool(ToolPose{Eigen::Vector3d(cut_x, y, -0.02), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
    tissue.step();
  }
  tissue.set_tool(ToolPose{Eigen::Vector3d(cut_x, y_to, -0.02), Eigen::Quaterniond::Identity(), ToolMode::none});
  tissue.step();
}

struct SurfaceCheck {
  int open_edges = 0;  ///< edges with other than one triangle each way
  int pieces = 0;      ///< sets of triangles joined through shared points
  int degenerate = 0;  ///< triangles naming a point twice
};

SurfaceCheck check_drawn_surface(const Tissue& tissue) {
  std::vector<std::array<int, 3>> triangles;
  tissue.for_each_drawn_triangle([&](const std::array<int, 3>& t) { triangles.push_back(t); });
  EXPECT_EQ(triangles.size(), tissue.drawn_triangle_count());
  SurfaceCheck check;
  std::map<std::pair<int, int>, int> directed;  // (from, to) -> triangles
  const auto points = static_cast<int>(tissue.current_positions_m().size() / 3);
  std::vector<int> parent(static_cast<size_t>(points));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int v) {
    while (parent[static_cast<size_t>(v)] != v)
      v = parent[static_cast<size_t>(v)] = parent[static_cast<size_t>(parent[static_cast<size_t>(v)])];
    return v;
  };
  for (const auto& t : triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) ++check.degenerate;
    for (int c = 0; c < 3; ++c) {
      EXPECT_LT(t[static_cast<size_t>(c)], points);
      ++directed[{t[static_cast<size_t>(c)], t[static_cast<size_t>((c + 1) % 3)]}];
      parent[static_cast<size_t>(root(t[static_cast<size_t>(c)]))] = root(t[static_cast<size_t>((c + 1) % 3)]);
    }
  }
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    if (count != 1 || back == directed.end() || back->second != 1) ++check.open_edges;
  }
  std::set<int> roots;
  for (const auto& t : triangles) roots.insert(root(t[0]));
  check.pieces = static_cast<int>(roots.size());
  return check;
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
  const double y_from = -0.005, y_to = 0.025;
  const int steps = static_cast<int>(std::ceil((y_to - y_from) / (0.2 * STEP_S)));
  int worst_open = 0;
  for (int n = 0; n <= steps; ++n) {
    const double y = y_from + (y_to - y_from) * n / steps;
    tissue.set_tool(ToolPose{Eigen::Vector3d(0.0553, y, -0.02), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
    tissue.step();
    worst_open = std::max(worst_open, check_drawn_surface(tissue).open_edges);
  }
  EXPECT_EQ(tissue.body().cut_tets().size(), 20u);
  EXPECT_EQ(worst_open, 0);
}

// A vertical scalpel drawn in a straight line from (x, y) `from` to `to` at 0.2 m/s, then put away;
// returns the most open edges the drawn surface had after any step.
int stroke_worst_open(Tissue& tissue, const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
  const int steps = static_cast<int>(std::ceil((to - from).norm() / (0.2 * STEP_S)));
  int worst_open = 0;
  for (int n = 0; n <= steps; ++n) {
    const Eigen::Vector2d at = from + (to - from) * n / steps;
    tissue.set_tool(
        ToolPose{Eigen::Vector3d(at.x(), at.y(), -0.02), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
    tissue.step();
    worst_open = std::max(worst_open, check_drawn_surface(tissue).open_edges);
  }
  tissue.set_tool(ToolPose{Eigen::Vector3d(to.x(), to.y(), -0.02), Eigen::Quaterniond::Identity(), ToolMode::none});
  tissue.step();
  return std::max(worst_open, check_drawn_surface(tissue).open_edges);
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

// Not yet closed (docs/DESIGN.md, "The tet skin welded"): where the second stroke's front crosses a
// mesh edge the first cut crosses too (an X; a T at y = 2.07 cm here), the first cut's corners on
// that edge in the tet cut twice and in its neighbour the second did not cut see the vertex beyond
// the second cut through different ghost rows, so they are not welded (24 to 48 open edges).
TEST(CutSurfaceWeld, DISABLED_CrossingStrokesStayClosedAtEveryStep) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  Tissue tissue(mesh, block_settings(mesh));
  EXPECT_EQ(stroke_worst_open(tissue, {0.0033, -0.005}, {0.0347, 0.045}), 0);
  EXPECT_EQ(stroke_worst_open(tissue, {0.0374, -0.005}, {0.0060, 0.045}), 0);
  EXPECT_EQ(check_drawn_surface(tissue).pieces, 4);
}

}  // namespace
}  // namespace tissue
