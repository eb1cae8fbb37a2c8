// The render surface cut with the tets (issue 22): after the volume cutter's strokes through the
// frog at rest, the render surface (meshes/frog_surface.obj) is split along the cuts and capped, and
// every piece cut free is a closed, consistently oriented surface (every edge run once each way by
// its triangles), enclosing the piece's simulated volume to within the render surface's bulge over
// the tets (the smooth surface lies outside the tets' flat faces by their sagitta: the uncut render
// surface encloses the tets' volume times a ratio r0, and each piece the same ratio to 1%). When the
// piece cut free falls 2 cm, nothing is stretched across the opening: no render triangle grows
// longer than 3 times the longest at rest.
#include "core/collide/surface_bvh.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "core/render/cut_render_surface.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <map>
#include <numeric>
#include <span>
#include <string>
#include <vector>

namespace tissue {
namespace {

constexpr double DENSITY = 1000.0;

/// The frog cut at rest by vertical strokes (x, y from -> to), each its own session.
struct CutFrog {
  TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  SurfaceMesh surface = extract_surface(mesh);
  TetAdjacency adjacency = build_adjacency(mesh);
  DeformableBody body;
  DynamicState state;

  explicit CutFrog(const std::vector<std::array<Eigen::Vector2d, 2>>& strokes, double held_below_x_m = -1.0)
      : body(mesh, settings(mesh, held_below_x_m)) {
    state.displacement_m = Eigen::VectorXd::Zero(body.dof_count());
    state.velocity_m_per_s = Eigen::VectorXd::Zero(body.dof_count());
    Eigen::VectorXd rest(3 * mesh.vertex_count());
    for (int v = 0; v < mesh.vertex_count(); ++v) rest.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<size_t>(v)];
    const SurfaceBvh bvh(surface.triangles, rest);
    VolumeCutter cutter(mesh, adjacency, surface);
    for (const auto& [from, to] : strokes) {
      Blade previous;
      constexpr int STEPS = 40;
      for (int n = 0; n <= STEPS; ++n) {
        const Eigen::Vector2d at = from + (to - from) * n / STEPS;
        const Blade blade{Eigen::Vector3d(at.x(), at.y(), -0.03), Eigen::Vector3d(at.x(), at.y(), 0.06)};
        cutter.step(n == 0 ? blade : previous, blade, rest, bvh);
        previous = blade;
        if (!cutter.new_cuts().empty()) body.enrich(cutter.new_cuts(), state);
      }
      cutter.end_cut();
    }
  }
  /// Gravity -z; the vertices behind `held_below_x_m` held.
  static BodySettings settings(const TetMesh& mesh, double held_below_x_m) {
    BodySettings settings;
    settings.material = Material{5.0e5, 0.3, DENSITY};
    settings.damping = RayleighDamping{1.0, 1e-3};
    settings.gravity_m_per_s2 = {0.0, 0.0, -9.81};
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      if (mesh.rest_positions_m[static_cast<size_t>(v)].x() < held_below_x_m) settings.fixed_vertices.push_back(v);
    }
    return settings;
  }
};

/// Connected parts of a triangle mesh (triangles joined by a shared edge): the part of each triangle.
std::vector<int> parts_of(const std::vector<std::array<int, 3>>& triangles, int& count) {
  std::vector<int> parent(triangles.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int i) {
    while (parent[static_cast<size_t>(i)] != i) i = parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    return i;
  };
  std::map<std::pair<int, int>, int> first_user;
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (size_t k = 0; k < 3; ++k) {
      const int u = triangles[t][k], v = triangles[t][(k + 1) % 3];
      const auto [it, added] = first_user.emplace(std::pair{std::min(u, v), std::max(u, v)}, static_cast<int>(t));
      if (!added) parent[static_cast<size_t>(find(static_cast<int>(t)))] = find(it->second);
    }
  }
  std::map<int, int> number;
  std::vector<int> part(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) {
    part[t] = number.emplace(find(static_cast<int>(t)), static_cast<int>(number.size())).first->second;
  }
  count = static_cast<int>(number.size());
  return part;
}

TEST(CutRenderSurface, ACompleteCutLeavesTwoClosedPiecesOfTheSimulatedVolumes) {
  // Across the body, a little behind the front legs, through the whole frog.
  const double cut_x = 0.0051;
  CutFrog frog({{Eigen::Vector2d(cut_x, -0.07), Eigen::Vector2d(cut_x, 0.07)}});
  ASSERT_GT(frog.body.cut_tet_count(), 50);
  CutRenderSurface render(frog.mesh, read_obj(std::string(TISSUE_MESH_DIR) + "/frog_surface.obj"),
                          default_max_outside_m(frog.mesh), "frog_surface.obj");
  render.rebuild(frog.body);
  render.update(frog.body, frog.state.displacement_m);
  const auto& triangles = render.triangles();
  const auto& x = render.positions_m();

  int count = 0;
  const std::vector<int> part = parts_of(triangles, count);
  ASSERT_EQ(count, 2);
  // Closed and consistently oriented: each directed edge once, and its twin once.
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : triangles) {
    for (size_t k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  int bad_edges = 0;
  for (const auto& [edge, uses] : directed) {
    const auto twin = directed.find({edge.second, edge.first});
    bad_edges += (uses != 1 || twin == directed.end() || twin->second != 1) ? 1 : 0;
  }
  EXPECT_EQ(bad_edges, 0);
  // Volumes: the render pieces against the simulated ones (rest volume behind and ahead of the cut).
  std::vector<double> render_m3(2, 0.0);
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& [a, b, c] = triangles[t];
    render_m3[static_cast<size_t>(part[t])] += x[static_cast<size_t>(a)].dot(x[static_cast<size_t>(b)].cross(x[static_cast<size_t>(c)])) / 6.0;
  }
  double behind_kg = 0.0, total_kg = frog.body.total_mass_kg();
  for (int t = 0; t < frog.mesh.tet_count(); ++t) {
    const int k = frog.body.cut_tet_index(t);
    const auto corners = frog.mesh.rest_corners(t);
    if (k < 0) {
      if ((corners[0] + corners[1] + corners[2] + corners[3]).x() / 4.0 < cut_x)
        behind_kg += DENSITY * signed_tet_volume(corners[0], corners[1], corners[2], corners[3]);
      continue;
    }
    const CutTetGeometry& geometry = frog.body.cut_geometry(k);
    for (int p = 0; p < static_cast<int>(geometry.pieces.size()); ++p) {
      if (piece_geometry(corners, geometry.cuts, geometry.pieces[static_cast<size_t>(p)].sides).centroid_m().x() < cut_x)
        behind_kg += frog.body.piece_mass_kg(k, p);
    }
  }
  // Which render part is behind: the one whose first vertex is.
  std::vector<double> simulated_m3(2);
  size_t first_of_part0 = 0;
  while (part[first_of_part0] != 0) ++first_of_part0;
  const bool part0_behind = render.rest_positions_m()[static_cast<size_t>(triangles[first_of_part0][0])].x() < cut_x;
  simulated_m3[part0_behind ? 0 : 1] = behind_kg / DENSITY;
  simulated_m3[part0_behind ? 1 : 0] = (total_kg - behind_kg) / DENSITY;
  const TriangleSurface uncut = read_obj(std::string(TISSUE_MESH_DIR) + "/frog_surface.obj");
  double uncut_m3 = 0.0;
  for (const auto& [a, b, c] : uncut.triangles)
    uncut_m3 += uncut.vertices_m[static_cast<size_t>(a)].dot(uncut.vertices_m[static_cast<size_t>(b)].cross(uncut.vertices_m[static_cast<size_t>(c)])) / 6.0;
  const double bulge = uncut_m3 / (total_kg / DENSITY);  // r0
  for (size_t p = 0; p < 2; ++p) {
    std::printf("piece %zu: render %.4g m3, simulated %.4g m3 (ratio %.4f, uncut %.4f)\n", p, render_m3[p],
                simulated_m3[p], render_m3[p] / simulated_m3[p], bulge);
    EXPECT_GT(render_m3[p], 0.0);
    EXPECT_NEAR(render_m3[p] / simulated_m3[p], bulge, 0.01);
  }
  std::printf("%zu triangles (%d caps), %d cut edges\n", triangles.size(), render.cap_triangle_count(),
              render.cut_edge_count());
}

double longest_edge_m(const std::vector<Eigen::Vector3d>& x, std::span<const std::array<int, 3>> triangles) {
  double longest = 0.0;
  for (const auto& t : triangles) {
    for (size_t k = 0; k < 3; ++k)
      longest = std::max(longest, (x[static_cast<size_t>(t[k])] - x[static_cast<size_t>(t[(k + 1) % 3])]).norm());
  }
  return longest;
}

TEST(CutRenderSurface, APieceThatFallsAwayStretchesNoTriangleAcrossTheOpening) {
  // The head end cut off across the body and falling; the hind part held (behind x = -0.02 m).
  const double cut_x = 0.0051;
  CutFrog frog({{Eigen::Vector2d(cut_x, -0.07), Eigen::Vector2d(cut_x, 0.07)}}, -0.02);
  CutRenderSurface render(frog.mesh, read_obj(std::string(TISSUE_MESH_DIR) + "/frog_surface.obj"),
                          default_max_outside_m(frog.mesh), "frog_surface.obj");
  render.rebuild(frog.body);
  render.update(frog.body, frog.state.displacement_m);
  const std::span<const std::array<int, 3>> all(render.triangles());
  const auto skin = all.first(all.size() - static_cast<size_t>(render.cap_triangle_count()));
  const auto caps = all.last(static_cast<size_t>(render.cap_triangle_count()));
  const double rest_longest_m = longest_edge_m(render.positions_m(), skin);
  const std::vector<Eigen::Vector3d> rest_x = render.positions_m();
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  // Until the cut-off part's render points have dropped 2 cm on average.
  const auto drop_m = [&] {
    double sum = 0.0;
    int count = 0;
    for (int i = 0; i < render.point_count(); ++i) {
      if (render.rest_positions_m()[static_cast<size_t>(i)].x() <= cut_x) continue;
      sum += render.rest_positions_m()[static_cast<size_t>(i)].z() - render.positions_m()[static_cast<size_t>(i)].z();
      ++count;
    }
    return sum / count;
  };
  int steps = 0;
  while (drop_m() < 0.02 && steps < 200) {
    integrator.step(frog.body, frog.state, 1e-3);
    render.update(frog.body, frog.state.displacement_m);
    ++steps;
  }
  ASSERT_GE(drop_m(), 0.02);
  const double longest_m = longest_edge_m(render.positions_m(), skin);
  // A cap spans its piece's opening and moves with it: its edges keep their length but for the
  // piece's strain.
  double worst_cap_strain = 0.0;
  for (const auto& t : caps) {
    for (size_t k = 0; k < 3; ++k) {
      const auto a = static_cast<size_t>(t[k]), b = static_cast<size_t>(t[(k + 1) % 3]);
      const double rest_m = (rest_x[a] - rest_x[b]).norm();
      if (rest_m > 1e-4) {
        worst_cap_strain = std::max(worst_cap_strain, std::abs((render.positions_m()[a] - render.positions_m()[b]).norm() / rest_m - 1.0));
      }
    }
  }
  std::printf("after %d steps: longest skin edge %.4g m (%.4g m at rest), caps strained by at most %.3g\n", steps,
              longest_m, rest_longest_m, worst_cap_strain);
  EXPECT_LT(longest_m, 3.0 * rest_longest_m);
  EXPECT_LT(worst_cap_strain, 0.1);
}

}  // namespace
}  // namespace tissue
