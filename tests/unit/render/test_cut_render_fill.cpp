// The holes peel_by_cuts fills are kept where they bound the solid they close (cut_render_fill.cpp):
// the winding number of a shell, and the probes behind and in front of a fill's largest triangles.
// And ear_clip (cut_render_loops.cpp), which caps the loops, on a loop that passes a point twice.
#include "core/render/cut_render_detail.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

namespace tissue {
namespace {

using Triangles = std::vector<std::array<int, 3>>;

// A 4 mm cube at `origin`, its 12 triangles outward; the top face (z = 4 mm) last.
void add_cube(const Eigen::Vector3d& origin, std::vector<Eigen::Vector3d>& x, Triangles& triangles) {
  const int first = static_cast<int>(x.size());
  for (int k = 0; k < 8; ++k) x.push_back(origin + 4e-3 * Eigen::Vector3d(k & 1, (k >> 1) & 1, (k >> 2) & 1));
  const std::array<std::array<int, 4>, 6> faces{{{0, 2, 3, 1},    // z = 0, outward -z
                                                 {0, 1, 5, 4},    // y = 0
                                                 {2, 6, 7, 3},    // y = 4 mm
                                                 {0, 4, 6, 2},    // x = 0
                                                 {1, 3, 7, 5},    // x = 4 mm
                                                 {4, 5, 7, 6}}};  // z = 4 mm, outward +z
  for (const auto& q : faces) {
    triangles.push_back({first + q[0], first + q[1], first + q[2]});
    triangles.push_back({first + q[0], first + q[2], first + q[3]});
  }
}

std::vector<size_t> all_of(const Triangles& triangles) {
  std::vector<size_t> shell(triangles.size());
  std::iota(shell.begin(), shell.end(), 0);
  return shell;
}

// The winding number of a closed outward shell: 1 inside, 0 outside, -1 inside it turned inside out.
TEST(WindingNumber, IsOneInsideAClosedShellAndZeroOutside) {
  std::vector<Eigen::Vector3d> x;
  Triangles cube;
  add_cube(Eigen::Vector3d::Zero(), x, cube);
  EXPECT_NEAR(cut_render_detail::winding_number(cube, all_of(cube), x, {2e-3, 1e-3, 3.9e-3}), 1.0, 1e-12);
  EXPECT_NEAR(cut_render_detail::winding_number(cube, all_of(cube), x, {2e-3, 1e-3, 4.1e-3}), 0.0, 1e-12);
  EXPECT_NEAR(cut_render_detail::winding_number(cube, all_of(cube), x, {-1.0, 5.0, 2.0}), 0.0, 1e-12);
  for (auto& t : cube) std::swap(t[1], t[2]);
  EXPECT_NEAR(cut_render_detail::winding_number(cube, all_of(cube), x, {2e-3, 1e-3, 3.9e-3}), -1.0, 1e-12);
}

// Four shells side by side. Kept: the closed outward cube's top face, and a sheet within a cube (a
// square's two faces back to back from the cube's corner into it: the cube winds once around it on
// both sides, no one sees it). Dropped: a sheet in the open (nothing behind it) and the top of a cube
// turned inside out (behind it is outside, in front inside: -1). Each shell is judged by its own
// triangles, whatever lies beside it.
TEST(FillsBoundingSolids, KeepsFacesOfTheSolidAndWithinItDropsSheetsInTheOpenAndTurnedShells) {
  std::vector<Eigen::Vector3d> x;
  Triangles triangles;
  std::vector<std::pair<size_t, size_t>> fills;
  add_cube(Eigen::Vector3d::Zero(), x, triangles);  // sound
  fills.emplace_back(triangles.size() - 2, triangles.size());

  const int square = static_cast<int>(x.size());  // a sheet 10 mm away: up and down
  for (const auto& corner : {Eigen::Vector3d(10e-3, 0, 0), Eigen::Vector3d(14e-3, 0, 0),
                             Eigen::Vector3d(14e-3, 4e-3, 0), Eigen::Vector3d(10e-3, 4e-3, 0)}) {
    x.push_back(corner);
  }
  triangles.push_back({square, square + 1, square + 2});
  triangles.push_back({square, square + 2, square + 3});
  triangles.push_back({square, square + 2, square + 1});
  triangles.push_back({square, square + 3, square + 2});
  fills.emplace_back(triangles.size() - 2, triangles.size());

  const size_t turned_first = triangles.size();
  add_cube(Eigen::Vector3d(20e-3, 0, 0), x, triangles);
  for (size_t t = turned_first; t < triangles.size(); ++t) std::swap(triangles[t][1], triangles[t][2]);
  fills.emplace_back(triangles.size() - 2, triangles.size());

  const size_t inner_cube = x.size();
  add_cube(Eigen::Vector3d(40e-3, 0, 0), x, triangles);
  const int corner = static_cast<int>(inner_cube), inside = static_cast<int>(x.size());
  x.push_back(x[inner_cube] + Eigen::Vector3d(3e-3, 1e-3, 1e-3));
  x.push_back(x[inner_cube] + Eigen::Vector3d(3e-3, 3e-3, 3e-3));
  x.push_back(x[inner_cube] + Eigen::Vector3d(1e-3, 1e-3, 3e-3));
  triangles.push_back({corner, inside, inside + 1});
  triangles.push_back({corner, inside + 1, inside + 2});
  triangles.push_back({corner, inside + 1, inside});
  triangles.push_back({corner, inside + 2, inside + 1});
  fills.emplace_back(triangles.size() - 4, triangles.size());

  const std::vector<char> sound = cut_render_detail::fills_bounding_solids(triangles, x, fills);
  EXPECT_EQ(sound, (std::vector<char>{1, 0, 0, 1}));
}

// Two openings of one cut touching at a surface vertex make one loop that passes it twice (the
// hatched frog through tissue-host: a 131-point loop). Clipped whole, a diagonal ran from a third
// point to both passes: one edge with four triangles. Now each lobe is clipped on its own: every
// directed edge once, each triangle wound as the loop, the lobes' area whole.
TEST(EarClip, ALoopThatPassesAPointTwiceIsClippedAsTwoLoops) {
  // Two lobes in z = 0 meeting at point 0, each wound counter-clockwise: 0 1 2 3 4 and 0 5 6 7 8.
  const std::vector<Eigen::Vector3d> x{{0, 0, 0},  {1, -1, 0}, {3, -1, 0},  {3, 1, 0},  {1, 1, 0},
                                       {-1, 1, 0}, {-3, 1, 0}, {-3, -1, 0}, {-1, -1, 0}};
  const std::vector<int> loop{0, 1, 2, 3, 4, 0, 5, 6, 7, 8};
  Triangles triangles;
  cut_render_detail::ear_clip(loop, x, triangles, [](int, int) { return false; });
  std::map<std::pair<int, int>, int> uses;
  double area = 0.0;
  for (const auto& [a, b, c] : triangles) {
    ++uses[{a, b}];
    ++uses[{b, c}];
    ++uses[{c, a}];
    const double z = (x[static_cast<size_t>(b)] - x[static_cast<size_t>(a)])
                         .cross(x[static_cast<size_t>(c)] - x[static_cast<size_t>(a)])
                         .z();
    EXPECT_GT(z, 0.0) << a << " " << b << " " << c;
    area += 0.5 * z;
  }
  for (const auto& [edge, count] : uses) EXPECT_EQ(count, 1) << edge.first << " -> " << edge.second;
  EXPECT_NEAR(area, 2 * 5.0, 1e-12);  // each lobe: a 2 x 2 square and a triangle of 1
}

}  // namespace
}  // namespace tissue
