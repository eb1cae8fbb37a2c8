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
#include "core/fem/body_parts.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "core/render/cut_render_detail.hpp"
#include "core/render/cut_render_surface.hpp"
#include "core/tissue.hpp"
#include "unit/material_parts.hpp"
#include "unit/render/box_surface.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <random>
#include <set>
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

  /// `after_cuts` is called after each blade step that cut.
  explicit CutFrog(const std::vector<std::array<Eigen::Vector2d, 2>>& strokes, double held_below_x_m = -1.0,
                   const std::function<void(const DeformableBody&)>& after_cuts = {})
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
        if (!cutter.new_cuts().empty()) {
          body.enrich(cutter.new_cuts(), state);
          if (after_cuts) after_cuts(body);
        }
      }
      cutter.end_cut(rest);  // the stroke ends where the blade is
      if (!cutter.new_cuts().empty()) {
        body.enrich(cutter.new_cuts(), state);
        if (after_cuts) after_cuts(body);
      }
    }
  }
  /// The frog's render surface (meshes/frog_surface.obj).
  static TriangleSurface render_surface() { return read_obj(std::string(TISSUE_MESH_DIR) + "/frog_surface.obj"); }
  /// The render surface cut with this frog's cuts, at rest.
  [[nodiscard]] CutRenderSurface cut_render_surface() const {
    CutRenderSurface render(mesh, render_surface(), default_max_outside_m(mesh), "frog_surface.obj");
    render.rebuild(body);
    return render;
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

double longest_edge_m(const std::vector<Eigen::Vector3d>& x, std::span<const std::array<int, 3>> triangles) {
  double longest = 0.0;
  for (const auto& t : triangles) {
    for (size_t k = 0; k < 3; ++k)
      longest = std::max(longest, (x[static_cast<size_t>(t[k])] - x[static_cast<size_t>(t[(k + 1) % 3])]).norm());
  }
  return longest;
}


/// The volume of the uncut render solid within the vertical prism where every plane of `inside` is
/// >= 0 (vertical planes): by the divergence theorem with the field (0, 0, z), the volume is the
/// integral of z n_z over the skin inside the prism, the vertical walls adding nothing; each skin
/// triangle is clipped to the prism (Sutherland-Hodgman). The render solid cut by ideal strokes.
double prism_volume_m3(const TriangleSurface& surface, const std::vector<CutPlane>& inside) {
  double volume = 0.0;
  for (const auto& t : surface.triangles) {
    std::vector<Eigen::Vector3d> polygon{surface.vertices_m[static_cast<size_t>(t[0])],
                                         surface.vertices_m[static_cast<size_t>(t[1])],
                                         surface.vertices_m[static_cast<size_t>(t[2])]};
    for (const CutPlane& plane : inside) {
      std::vector<Eigen::Vector3d> kept;
      for (size_t i = 0; i < polygon.size(); ++i) {
        const Eigen::Vector3d& a = polygon[i];
        const Eigen::Vector3d& b = polygon[(i + 1) % polygon.size()];
        const double da = plane.signed_distance(a), db = plane.signed_distance(b);
        if (da >= 0.0) kept.push_back(a);
        if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) kept.push_back(a + (b - a) * (da / (da - db)));
      }
      polygon = std::move(kept);
      if (polygon.size() < 3) break;
    }
    for (size_t i = 1; i + 1 < polygon.size(); ++i) {
      const Eigen::Vector3d area = 0.5 * (polygon[i] - polygon[0]).cross(polygon[i + 1] - polygon[0]);
      volume += area.z() * (polygon[0].z() + polygon[i].z() + polygon[i + 1].z()) / 3.0;
    }
  }
  return volume;
}

/// What the render cut may lose at a junction, where two strokes meet: the split points next to it
/// stand up to a render edge from it, so each piece's faces meet along a line about an edge inside
/// its corner, cutting off at most (longest render edge)^2 of its plan along the frog's height. [m^3]
double junction_tolerance_m3(const TriangleSurface& surface) {
  double longest_m = 0.0;
  double low_z = surface.vertices_m[0].z(), high_z = low_z;
  for (const auto& t : surface.triangles) {
    for (size_t k = 0; k < 3; ++k) {
      longest_m = std::max(longest_m, (surface.vertices_m[static_cast<size_t>(t[k])] -
                                       surface.vertices_m[static_cast<size_t>(t[(k + 1) % 3])]).norm());
    }
  }
  for (const auto& v : surface.vertices_m) {
    low_z = std::min(low_z, v.z());
    high_z = std::max(high_z, v.z());
  }
  return longest_m * longest_m * (high_z - low_z);
}

/// A vertical stroke's plane (seen from above, from `from` to `to`), positive on the side of `side`.
CutPlane stroke_plane(const Eigen::Vector2d& from, const Eigen::Vector2d& to, const Eigen::Vector3d& side) {
  const Eigen::Vector2d d = to - from;
  CutPlane plane{Eigen::Vector3d(-d.y(), d.x(), 0.0).normalized(), 0.0};
  plane.offset = plane.normal.dot(Eigen::Vector3d(from.x(), from.y(), 0.0));
  if (plane.signed_distance(side) < 0.0) plane = CutPlane{-plane.normal, -plane.offset};
  return plane;
}

struct RenderPart {
  double volume_m3 = 0.0;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();  ///< mean of its points (rest)
};

/// The render surface after the frog's cuts: as many parts as the body has material parts, each
/// closed and consistently oriented (every directed edge once, its twin once), each enclosing its
/// material part's volume to within the mesh's resolution (parts matched largest to largest): the
/// smooth render surface lies outside the tets' flat faces where the shape is convex and inside
/// where it is concave (the uncut one encloses r0 = 1.042 times their volume), so a part's ratio lies
/// within 0.08 of 1 (for parts of at least `judged_m3`: the bulge is the tets' sagitta over the part's
/// size, 17% for the frog's toes of 1 cm^3). Returns the parts (rest volumes and centroids).
/// With `shells_per_part_may_exceed_one`, a material part may be drawn as several closed shells (held
/// together by a piece too small for a later cut to split, which the render surface's planes do split).
std::vector<RenderPart> expect_closed_parts(const CutRenderSurface& render, const CutFrog& frog,
                                            double judged_m3 = 0.0, bool shells_per_part_may_exceed_one = false) {
  const auto& triangles = render.triangles();
  const auto& x = render.rest_positions_m();
  int count = 0;
  const std::vector<int> part = parts_of(triangles, count);
  const std::vector<double> simulated_m3 = material_part_volumes_m3(frog.mesh, frog.body);
  if (shells_per_part_may_exceed_one) {
    EXPECT_GE(count, static_cast<int>(simulated_m3.size()));
  } else {
    EXPECT_EQ(count, static_cast<int>(simulated_m3.size()));
  }
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
  std::vector<RenderPart> parts(static_cast<size_t>(count));
  std::vector<std::map<int, bool>> points(static_cast<size_t>(count));
  for (size_t t = 0; t < triangles.size(); ++t) {
    const auto& [a, b, c] = triangles[t];
    RenderPart& into = parts[static_cast<size_t>(part[t])];
    into.volume_m3 += x[static_cast<size_t>(a)].dot(x[static_cast<size_t>(b)].cross(x[static_cast<size_t>(c)])) / 6.0;
    for (const int q : triangles[t]) points[static_cast<size_t>(part[t])][q] = true;
  }
  for (size_t p = 0; p < parts.size(); ++p) {
    for (const auto& [q, unused] : points[p]) parts[p].centroid_m += x[static_cast<size_t>(q)] / static_cast<double>(points[p].size());
  }
  std::vector<double> render_m3;
  for (const RenderPart& p : parts) render_m3.push_back(p.volume_m3);
  std::sort(render_m3.rbegin(), render_m3.rend());
  for (size_t p = 0; p < std::min(render_m3.size(), simulated_m3.size()); ++p) {
    std::printf("part %zu: render %.4g m3, simulated %.4g m3, ratio %.4f\n", p, render_m3[p], simulated_m3[p],
                render_m3[p] / simulated_m3[p]);
    if (simulated_m3[p] >= judged_m3) {
      EXPECT_NEAR(render_m3[p] / simulated_m3[p], 1.0, 0.08);
    }
  }
  return parts;
}

TEST(CutRenderSurface, ACompleteCutLeavesTwoClosedPiecesOfTheSimulatedVolumes) {
  // Across the body, a little behind the front legs, through the whole frog.
  CutFrog frog({{Eigen::Vector2d(0.0051, -0.07), Eigen::Vector2d(0.0051, 0.07)}});
  ASSERT_GT(frog.body.cut_tet_count(), 50);
  CutRenderSurface render = frog.cut_render_surface();
  EXPECT_EQ(material_part_volumes_m3(frog.mesh, frog.body).size(), 2U);
  EXPECT_EQ(render.open_loop_count(), 0);
  const TriangleSurface uncut = CutFrog::render_surface();
  for (const RenderPart& part : expect_closed_parts(render, frog)) {
    const double ideal_m3 = prism_volume_m3(
        uncut, {stroke_plane(Eigen::Vector2d(0.0051, -0.07), Eigen::Vector2d(0.0051, 0.07), part.centroid_m)});
    std::printf("piece at x %.4f: %.6g m3, the render solid cut by the plane %.6g m3\n", part.centroid_m.x(),
                part.volume_m3, ideal_m3);
    EXPECT_NEAR(part.volume_m3, ideal_m3, 1e-9 * ideal_m3);  // no junction: exact
  }
}

// The room a render surface holds for split points and caps is there from its construction and the
// first cuts fit in it: none of its per-point arrays is re-allocated inside the cut's step (the
// organ's first cut re-allocated its 41k points' arrays inside a real-time slot: 13-49 ms steps).
TEST(CutRenderSurface, ACompleteCutFitsTheRoomHeldFromConstruction) {
  std::unique_ptr<CutRenderSurface> render;
  size_t points = 0, triangles = 0, surface_vertices = 0, rebuilds = 0;
  bool grew = false;
  const CutFrog frog({{Eigen::Vector2d(0.0051, -0.07), Eigen::Vector2d(0.0051, 0.07)}}, -1.0,
                     [&](const DeformableBody& body) {
                       if (!render) {  // made before its first re-mesh: the room as constructed
                         const TriangleSurface surface = CutFrog::render_surface();
                         surface_vertices = surface.vertices_m.size();
                         render = std::make_unique<CutRenderSurface>(body.mesh(), surface,
                                                                     default_max_outside_m(body.mesh()), "frog");
                         points = render->point_room();
                         triangles = render->triangle_room();
                       }
                       render->rebuild(body);
                       ++rebuilds;
                       grew = grew || render->point_room() != points || render->triangle_room() != triangles;
                     });
  ASSERT_TRUE(render);
  EXPECT_GT(rebuilds, 5u);
  EXPECT_GE(points, surface_vertices + surface_vertices / 2);
  EXPECT_GT(static_cast<size_t>(render->point_count()), surface_vertices);  // split points were made
  EXPECT_FALSE(grew);
  EXPECT_EQ(render->open_loop_count(), 0);
}

// The normals are found when read (issue 42: the FMU's frames read the embedding and the nodes alone),
// and always of the positions as the last update left them: after an update that moves every
// unknown, what normals() gives is vertex_normals of the new positions, not of the old.
TEST(CutRenderSurface, NormalsReadAfterAnUpdateAreThoseOfItsPositions) {
  CutFrog frog({{Eigen::Vector2d(0.0051, -0.07), Eigen::Vector2d(0.0051, 0.07)}});
  CutRenderSurface render = frog.cut_render_surface();
  std::vector<Eigen::Vector3d> expected;
  for (int pass = 0; pass < 2; ++pass) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(frog.body.dof_count());
    for (Eigen::Index i = 0; i < u.size(); ++i) u(i) = 1e-3 * pass * std::sin(0.37 * static_cast<double>(i));
    render.update(frog.body, u);
    vertex_normals(render.positions_m(), render.triangles(), expected);
    ASSERT_EQ(render.normals().size(), expected.size());
    double largest = 0.0;
    for (size_t v = 0; v < expected.size(); ++v) largest = std::max(largest, (render.normals()[v] - expected[v]).norm());
    EXPECT_EQ(largest, 0.0) << "pass " << pass;
  }
}

TEST(CutRenderSurface, APartialCutIsASlitWithAWallOnEachSide) {
  // From the side of the body to its middle, through the whole height: the frog stays one piece, its
  // surface closed, the slit's two walls meeting along the crack front.
  CutFrog frog({{Eigen::Vector2d(0.0051, -0.07), Eigen::Vector2d(0.0051, 0.0)}});
  ASSERT_GT(frog.body.cut_tet_count(), 20);
  CutRenderSurface render = frog.cut_render_surface();
  EXPECT_EQ(material_part_volumes_m3(frog.mesh, frog.body).size(), 1U);
  EXPECT_EQ(render.open_loop_count(), 0);
  EXPECT_GT(render.cap_triangle_count(), 0);
  expect_closed_parts(render, frog);
}

TEST(CutRenderSurface, AnXLeavesFourClosedPiecesOfTheSimulatedVolumes) {
  // Two strokes crossing on the back, each through the whole frog.
  CutFrog frog({{Eigen::Vector2d(-0.0301, -0.0702), Eigen::Vector2d(0.0399, 0.0698)},
                {Eigen::Vector2d(-0.0301, 0.0698), Eigen::Vector2d(0.0399, -0.0702)}});
  CutRenderSurface render = frog.cut_render_surface();
  EXPECT_EQ(material_part_volumes_m3(frog.mesh, frog.body).size(), 4U);
  EXPECT_EQ(render.open_loop_count(), 0);
  const TriangleSurface uncut = CutFrog::render_surface();
  for (const RenderPart& part : expect_closed_parts(render, frog)) {
    const double ideal_m3 = prism_volume_m3(
        uncut, {stroke_plane(Eigen::Vector2d(-0.0301, -0.0702), Eigen::Vector2d(0.0399, 0.0698), part.centroid_m),
                stroke_plane(Eigen::Vector2d(-0.0301, 0.0698), Eigen::Vector2d(0.0399, -0.0702), part.centroid_m)});
    std::printf("quadrant at (%.4f, %.4f): %.6g m3, the render solid cut by the strokes %.6g m3 (junction %.3g)\n",
                part.centroid_m.x(), part.centroid_m.y(), part.volume_m3, ideal_m3, junction_tolerance_m3(uncut));
    EXPECT_NEAR(part.volume_m3, ideal_m3, junction_tolerance_m3(uncut));  // one junction
  }
}

// Strokes through the held tail (issue 41: its pieces take held copies of the fixed vertices): one
// along the whole body and one across inside the held third leave four material parts (the halves,
// each with its tail's end cut off in the clamp), each drawn closed with its volume.
TEST(CutRenderSurface, StrokesThroughHeldMaterialLeaveClosedPieces) {
  CutFrog frog({{Eigen::Vector2d(-0.09, 0.0051), Eigen::Vector2d(0.08, 0.0051)},
                {Eigen::Vector2d(-0.0553, -0.07), Eigen::Vector2d(-0.0553, 0.07)}},
               -0.032);
  ASSERT_GT(frog.body.held_copies().size(), 0u);
  CutRenderSurface render = frog.cut_render_surface();
  EXPECT_EQ(render.open_loop_count(), 0);
  EXPECT_EQ(expect_closed_parts(render, frog, 2e-6).size(), 4u);
}

TEST(CutRenderSurface, AFlapCutFreeByThreeStrokesIsClosed) {
  // The flap of the crossing-cuts test: three strokes overshooting each other's corners by 2 cm (so
  // partial cuts run on beyond each corner).
  const std::array<Eigen::Vector2d, 3> corner{Eigen::Vector2d(-0.0213, -0.0117), Eigen::Vector2d(0.0161, -0.0129),
                                              Eigen::Vector2d(-0.0019, 0.0147)};
  std::vector<std::array<Eigen::Vector2d, 2>> strokes;
  for (size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d along = (corner[(k + 1) % 3] - corner[k]).normalized();
    strokes.push_back({corner[k] - 0.02 * along, corner[(k + 1) % 3] + 0.02 * along});
  }
  CutFrog frog(strokes);
  CutRenderSurface render = frog.cut_render_surface();
  EXPECT_EQ(render.open_loop_count(), 0);
  // The flap: the part whose centroid lies inside the triangle.
  const Eigen::Vector2d centre = (corner[0] + corner[1] + corner[2]) / 3.0;
  std::vector<CutPlane> inside;
  for (size_t k = 0; k < 3; ++k)
    inside.push_back(stroke_plane(corner[k], corner[(k + 1) % 3], Eigen::Vector3d(centre.x(), centre.y(), 0.0)));
  const TriangleSurface uncut = CutFrog::render_surface();
  const double ideal_m3 = prism_volume_m3(uncut, inside);
  int flaps = 0;
  for (const RenderPart& part : expect_closed_parts(render, frog)) {
    if (!std::all_of(inside.begin(), inside.end(), [&](const CutPlane& plane) { return plane.signed_distance(part.centroid_m) > 0.0; }))
      continue;
    ++flaps;
    std::printf("flap: %.6g m3, the render solid cut by the strokes %.6g m3\n", part.volume_m3, ideal_m3);
    EXPECT_NEAR(part.volume_m3, ideal_m3, 3.0 * junction_tolerance_m3(uncut));  // three corners
  }
  EXPECT_EQ(flaps, 1);
}

// The skin's triangles by their corners' rest positions (a split point's is exact: the same fraction
// of the same edge), each with its corners' positions at the last update, sorted: two re-meshes are
// the same skin, mapped alike, whatever their point numbering.
std::vector<std::pair<std::array<double, 9>, std::array<double, 9>>> skin_at_rest(const CutRenderSurface& render) {
  std::vector<std::pair<std::array<double, 9>, std::array<double, 9>>> skin;
  const auto& triangles = render.triangles();
  for (size_t t = 0; t + static_cast<size_t>(render.cap_triangle_count()) < triangles.size(); ++t) {
    std::array<double, 9> corners{}, mapped{};
    for (size_t k = 0; k < 3; ++k) {
      for (int c = 0; c < 3; ++c) {
        corners[3 * k + static_cast<size_t>(c)] = render.rest_positions_m()[static_cast<size_t>(triangles[t][k])](c);
        mapped[3 * k + static_cast<size_t>(c)] =
            render.positions_m().empty() ? 0.0 : render.positions_m()[static_cast<size_t>(triangles[t][k])](c);
      }
    }
    // Start at the smallest corner (the winding kept).
    size_t first = 0;
    for (size_t k = 1; k < 3; ++k) {
      if (std::lexicographical_compare(corners.begin() + 3 * k, corners.begin() + 3 * k + 3,
                                       corners.begin() + 3 * first, corners.begin() + 3 * first + 3)) {
        first = k;
      }
    }
    std::array<double, 9> rotated{}, rotated_mapped{};
    for (size_t k = 0; k < 9; ++k) {
      rotated[k] = corners[(k + 3 * first) % 9];
      rotated_mapped[k] = mapped[(k + 3 * first) % 9];
    }
    skin.emplace_back(rotated, rotated_mapped);
  }
  std::sort(skin.begin(), skin.end());
  return skin;
}

// The signed volume the whole render surface encloses at rest (its pieces' sum). [m^3]
double enclosed_at_rest_m3(const CutRenderSurface& render) {
  double six_v = 0.0;
  for (const auto& [a, b, c] : render.triangles()) {
    const auto& x = render.rest_positions_m();
    six_v += x[static_cast<size_t>(a)].dot(x[static_cast<size_t>(b)].cross(x[static_cast<size_t>(c)]));
  }
  return six_v / 6.0;
}

// Re-meshing after every blade step that cut redoes only the tets whose cut changed (and their
// neighbours) and keeps the rest, also at the steps where a piece comes free (the material parts
// regroup); at every 7th step, at the steps where the parts regroup and at the end it is the
// surface re-meshed from scratch for the same cuts: the same skin triangles (corner for corner at
// rest, and mapped onto a state that moves every unknown to the same positions bitwise: the same
// pieces), as many open loops, and the same enclosed volume (the caps lie in their cut planes, so
// how they are triangulated does not change it: to round-off). The caps' triangles: as many for the
// X and the flap; within 1% for 3 + 3 hatched strokes (re-cut tets, many crack tips: where several
// tips of one cut lie on a loop, which pairs with which follows the loop's order, and so the points'
// numbering).
TEST(CutRenderSurface, ReMeshingStepByStepIsReMeshingFromScratch) {
  const std::array<Eigen::Vector2d, 3> corner{Eigen::Vector2d(-0.0213, -0.0117), Eigen::Vector2d(0.0161, -0.0129),
                                              Eigen::Vector2d(-0.0019, 0.0147)};
  std::vector<std::array<Eigen::Vector2d, 2>> flap;
  for (size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d along = (corner[(k + 1) % 3] - corner[k]).normalized();
    flap.push_back({corner[k] - 0.02 * along, corner[(k + 1) % 3] + 0.02 * along});
  }
  std::vector<std::array<Eigen::Vector2d, 2>> hatched;
  for (int k = 0; k < 3; ++k) hatched.push_back({Eigen::Vector2d(-0.025 + 0.02 * (k + 0.5), -0.0702), Eigen::Vector2d(-0.025 + 0.02 * (k + 0.5), 0.0698)});
  for (int k = 0; k < 3; ++k) hatched.push_back({Eigen::Vector2d(-0.0301, -0.05 + 0.0333 * (k + 0.5)), Eigen::Vector2d(0.0399, -0.05 + 0.0333 * (k + 0.5))});
  const std::vector<std::vector<std::array<Eigen::Vector2d, 2>>> cases{
      {{Eigen::Vector2d(-0.0301, -0.0702), Eigen::Vector2d(0.0399, 0.0698)},
       {Eigen::Vector2d(-0.0301, 0.0698), Eigen::Vector2d(0.0399, -0.0702)}},
      flap, hatched};
  const TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  const CutRenderSurface pristine(mesh, CutFrog::render_surface(), default_max_outside_m(mesh));
  for (size_t c = 0; c < cases.size(); ++c) {
    CutRenderSurface stepwise = pristine;
    int steps = 0, incremental = 0, regroups = 0, parts = 1;
    const CutFrog frog(cases[c], -1.0, [&](const DeformableBody& body) {
      stepwise.rebuild(body);
      ++steps;
      incremental += stepwise.rebuilt_from_scratch() ? 0 : 1;
      const int now_parts = find_body_parts(body).count();
      const bool regrouped = now_parts != parts;
      regroups += regrouped ? 1 : 0;
      parts = now_parts;
      if (steps % 7 != 0 && !regrouped) return;  // compared then (and at the end)
      CutRenderSurface scratch = pristine;
      scratch.rebuild(body);
      ASSERT_TRUE(scratch.rebuilt_from_scratch());
      // Both mapped onto the same state with every unknown moved (ghosts too): the points ride on
      // the same pieces.
      std::mt19937 rng(static_cast<unsigned>(steps));
      std::uniform_real_distribution<double> move(-1e-3, 1e-3);
      Eigen::VectorXd displacement_m(body.dof_count());
      for (Eigen::Index i = 0; i < displacement_m.size(); ++i) displacement_m(i) = move(rng);
      stepwise.update(body, displacement_m);
      scratch.update(body, displacement_m);
      const double cap_tolerance = c == 2 ? 0.01 * scratch.cap_triangle_count() : 0.0;
      EXPECT_NEAR(stepwise.cap_triangle_count(), scratch.cap_triangle_count(), cap_tolerance) << "case " << c << " step " << steps;
      EXPECT_EQ(stepwise.open_loop_count(), scratch.open_loop_count()) << "case " << c << " step " << steps;
      EXPECT_TRUE(skin_at_rest(stepwise) == skin_at_rest(scratch)) << "case " << c << " step " << steps;
      EXPECT_NEAR(enclosed_at_rest_m3(stepwise), enclosed_at_rest_m3(scratch), 1e-15) << "case " << c << " step " << steps;
    });
    CutRenderSurface scratch = pristine;
    scratch.rebuild(frog.body);
    const Eigen::VectorXd displacement_m = Eigen::VectorXd::Constant(frog.body.dof_count(), 1e-4);
    stepwise.update(frog.body, displacement_m);
    scratch.update(frog.body, displacement_m);
    EXPECT_TRUE(skin_at_rest(stepwise) == skin_at_rest(scratch)) << "case " << c;
    EXPECT_NEAR(stepwise.cap_triangle_count(), scratch.cap_triangle_count(), c == 2 ? 0.01 * scratch.cap_triangle_count() : 0.0)
        << "case " << c;
    EXPECT_EQ(stepwise.open_loop_count(), scratch.open_loop_count()) << "case " << c;
    EXPECT_NEAR(enclosed_at_rest_m3(stepwise), enclosed_at_rest_m3(scratch), 1e-15) << "case " << c;
    std::printf("case %zu: %d re-meshes, %d incremental, %d with the parts regrouped\n", c, steps, incremental,
                regroups);
    // From scratch the first time, and at most once more when dropped split points pile up.
    EXPECT_GE(incremental, steps - 2) << "case " << c;
    EXPECT_GT(regroups, 0) << "case " << c;
  }
}

TEST(CutRenderSurface, APieceThatFallsAwayStretchesNoTriangleAcrossTheOpening) {
  // The head end cut off across the body and falling; the hind part held (behind x = -0.02 m).
  const double cut_x = 0.0051;
  CutFrog frog({{Eigen::Vector2d(cut_x, -0.07), Eigen::Vector2d(cut_x, 0.07)}}, -0.02);
  CutRenderSurface render = frog.cut_render_surface();
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

// The Tissue keeps the render surface of its scene up to date on demand: a scalpel stroke across a
// cantilever beam (held at x = 0) through its whole height cuts its free end off, and the render
// surface (a box surface of 2 mm squares) falls into two closed pieces; a snapshot restored into a
// fresh Tissue (its cuts replayed) draws the same surface at the same positions, bitwise.
TEST(TissueRenderSurface, TheScalpelsCutIsDrawnOnTheRenderSurfaceAndSurvivesARestore) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  TissueSettings settings;
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.0);
  settings.interaction.cutting_enabled = true;
  settings.interaction.blade_length_m = 0.06;
  settings.render_surface = std::make_shared<const TriangleSurface>(box_surface(Eigen::Vector3d(0.1, 0.02, 0.02), 10));
  auto tissue = std::make_unique<Tissue>(mesh, settings);
  const CutRenderSurface* render = tissue->render_surface();
  ASSERT_NE(render, nullptr);
  EXPECT_EQ(render->cut_edge_count(), 0);
  const size_t uncut_triangles = render->triangles().size();
  for (int n = 0; n <= 30; ++n) {
    const double y = -0.005 + 0.03 * n / 30.0;
    tissue->set_tool({Eigen::Vector3d(0.0553, y, -0.02), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
    tissue->step();
  }
  tissue->set_tool({Eigen::Vector3d(0.0553, 0.025, -0.02), Eigen::Quaterniond::Identity(), ToolMode::none});
  for (int n = 0; n < 20; ++n) tissue->step();
  ASSERT_EQ(material_part_volumes_m3(mesh, tissue->body()).size(), 2U);
  render = tissue->render_surface();
  EXPECT_GT(render->cut_edge_count(), 10);
  EXPECT_GT(render->triangles().size(), uncut_triangles);
  int parts = 0;
  (void)parts_of(render->triangles(), parts);
  EXPECT_EQ(parts, 2);
  EXPECT_EQ(render->open_loop_count(), 0);
  // The free end fell (the core's gravity is along -y): its render points moved down with it.
  ASSERT_EQ(settings.body.gravity_m_per_s2, Eigen::Vector3d(0.0, -9.81, 0.0));
  double lowest_y = 0.0;
  for (const auto& p : render->positions_m()) lowest_y = std::min(lowest_y, p.y());
  EXPECT_LT(lowest_y, -1e-4);

  TissueSnapshot snapshot;
  tissue->save(snapshot);
  auto fresh = std::make_unique<Tissue>(mesh, settings);
  restore_or_replay(fresh, snapshot);
  const CutRenderSurface* again = fresh->render_surface();
  ASSERT_EQ(again->triangles(), render->triangles());
  ASSERT_EQ(again->positions_m().size(), render->positions_m().size());
  for (size_t i = 0; i < render->positions_m().size(); ++i) ASSERT_EQ(again->positions_m()[i], render->positions_m()[i]);
  // A render surface that does not fit the mesh is refused.
  TriangleSurface far = *settings.render_surface;
  far.vertices_m[7] += Eigen::Vector3d(0.0, 0.0, 0.05);
  settings.render_surface = std::make_shared<const TriangleSurface>(far);
  EXPECT_THROW(Tissue(mesh, settings), ParameterError);
}

}  // namespace
}  // namespace tissue

namespace tissue {
namespace {

// N strokes across the frog through its whole width and N along its middle that end inside it (the
// benchmark's hatching, BM_CutRenderSurfaceHatched): the strokes along run into the body and out of the
// cuts across, on planes through the render surface's vertices (y = 0 is the frog's plane of symmetry).
std::vector<std::array<Eigen::Vector2d, 2>> hatching(int strokes) {
  std::vector<std::array<Eigen::Vector2d, 2>> hatched;
  for (int k = 0; k < strokes; ++k) {
    const double x = -0.025 + 0.06 * (k + 0.5) / strokes;
    hatched.push_back({Eigen::Vector2d(x, -0.0702), Eigen::Vector2d(x, 0.0698)});
  }
  for (int k = 0; k < strokes; ++k) {
    const double y = -0.05 + 0.10 * (k + 0.5) / strokes;
    hatched.push_back({Eigen::Vector2d(-0.0301, y), Eigen::Vector2d(0.0399, y)});
  }
  return hatched;
}

// Where a stroke ends inside the body next to another cut, its crack turns away from the junction
// inside the body: the through cut's face has a notch (the junction down to where the crack leaves
// it) and the walls close along it and the crack front. Strokes closer than a tet (10 + 10: 6 mm
// apart) give one quadrant of a part several junction lines, each closed between the switches it
// joins. Before, those loops stayed open (1 + 1: 4 open loops, 3 + 3: 3, 10 + 10: 25) and the
// pieces had holes. At 10 + 10 five parts are drawn as two shells each (59 parts, 64 shells).
TEST(CutRenderSurface, HatchedStrokesEndingInsideLeaveClosedPieces) {
  for (const int strokes : {1, 3, 10}) {
    CutFrog frog(hatching(strokes));
    CutRenderSurface render = frog.cut_render_surface();
    EXPECT_EQ(render.open_loop_count(), 0) << strokes << " + " << strokes;
    expect_closed_parts(render, frog, 5e-6, strokes > 3);  // the frog is 8.1e-5 m^3
  }
}

// 14 strokes across, 4.3 mm apart (closer than the tets), and one along the frog's plane of symmetry:
// where the points of a cut's chain ride only on uncut tets, the chain faces neither side of its cut,
// and its switch is keyed apart from its partner's; it now joins the one lone switch keyed like it but
// for that side. Before: 4 open loops.
TEST(CutRenderSurface, AChainFacingNeitherSideStillJoinsItsPartnerAtTheJunction) {
  std::vector<std::array<Eigen::Vector2d, 2>> strokes;
  for (int k = 0; k < 14; ++k) {
    const double x = -0.025 + 0.06 * (k + 0.5) / 14;
    strokes.push_back({Eigen::Vector2d(x, -0.0702), Eigen::Vector2d(x, 0.0698)});
  }
  strokes.push_back({Eigen::Vector2d(-0.0301, 0.0), Eigen::Vector2d(0.0399, 0.0)});
  CutFrog frog(strokes);
  CutRenderSurface render = frog.cut_render_surface();
  EXPECT_EQ(render.open_loop_count(), 0);
  // Closed and oriented, at least a shell per material part; the slabs are thinner than the tets, so
  // a part may be drawn as several shells and the shells are judged together: they enclose the
  // body's simulated volume as the uncut render surface does (r0 = 1.042 times), to within 8%.
  double render_m3 = 0.0, simulated_m3 = 0.0;
  for (const RenderPart& part : expect_closed_parts(render, frog, std::numeric_limits<double>::infinity(), true))
    render_m3 += part.volume_m3;
  for (const double v : material_part_volumes_m3(frog.mesh, frog.body)) simulated_m3 += v;
  EXPECT_NEAR(render_m3 / simulated_m3, 1.042, 0.08);
}

}  // namespace
}  // namespace tissue
namespace tissue {
namespace {

// The border loops of `triangles` (directed edges without a twin, walked), counted by the test itself.
std::vector<std::vector<int>> border_loops_of(const std::vector<std::array<int, 3>>& triangles) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : triangles) {
    for (size_t k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  std::multimap<int, int> next;
  for (const auto& [edge, uses] : directed) {
    if (!directed.contains({edge.second, edge.first})) next.emplace(edge.first, edge.second);
  }
  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    std::vector<int> loop{next.begin()->first};
    for (auto at = next.begin(); at != next.end(); at = next.find(loop.back())) {
      const int to = at->second;
      next.erase(at);
      if (to == loop.front()) break;
      loop.push_back(to);
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

// 30 + 30 hatched strokes, 2 mm apart: the chain walk cannot close every face there (issue 41, item
// 4). What it leaves is reported as the surface's holes, which the test counts itself, and none of
// them is flat or two flat faces: those are faces the walk missed, now filled (before: 378 holes,
// 185 of them within 0.1 mm of their plane; then 116-120; 109 since holes are also filled by their
// cuts' faces where the part then encloses its simulated volume, most such fills here would not; 27
// since those that bound the solid they close as drawn are kept too; 10 since the holes whose faces
// neither rule keeps are peeled again in other orders: the issue's target is 17, 1% of the 1713 open
// loops it was filed with). No edge is run twice the same way (a fill on top of another).
TEST(CutRenderSurface, DenseHatchingLeavesNoFlatHole) {
  CutFrog frog(hatching(30));
  CutRenderSurface render = frog.cut_render_surface();
  const std::vector<std::vector<int>> holes = border_loops_of(render.triangles());
  EXPECT_EQ(render.open_loop_count(), static_cast<int>(holes.size()));
  EXPECT_GT(render.open_loop_count(), 0);  // not closed yet: say so in docs/BENCHMARKS.md when it is
  EXPECT_LE(render.open_loop_count(), 17);
  std::set<std::pair<int, int>> directed;
  int repeated = 0;
  for (const std::array<int, 3>& t : render.triangles()) {
    for (int k = 0; k < 3; ++k)
      repeated += directed.emplace(t[static_cast<size_t>(k)], t[static_cast<size_t>((k + 1) % 3)]).second ? 0 : 1;
  }
  EXPECT_EQ(repeated, 0);
  int flat = 0, two_flat = 0;
  for (const std::vector<int>& hole : holes) {
    flat += cut_render_detail::flat_within(hole, render.rest_positions_m(), 1e-4);
    std::vector<std::vector<int>> halves;
    two_flat += cut_render_detail::split_in_two_flat(hole, render.rest_positions_m(), halves);
  }
  EXPECT_EQ(flat, 0);
  EXPECT_EQ(two_flat, 0);
}

// A hole on two planes (an L: 3 mm along x on the floor z = 0, then 2 mm up the wall x = 3 mm) is
// split along the junction (the chord between its two points on the line x = 3 mm, z = 0) into
// two flat faces; a hole twisted out of any two planes is not.
TEST(SplitInTwoFlat, SplitsAHoleOnTwoPlanesAlongTheirJunction) {
  const std::vector<Eigen::Vector3d> x{{0, 0, 0},     {1e-3, 0, 0},    {2e-3, 0, 0},    {3e-3, 0, 0},
                                       {3e-3, 0, 1e-3}, {3e-3, 0, 2e-3}, {3e-3, 2e-3, 2e-3}, {3e-3, 2e-3, 1e-3},
                                       {3e-3, 2e-3, 0}, {2e-3, 2e-3, 0}, {0, 2e-3, 0}};
  std::vector<int> loop(x.size());
  std::iota(loop.begin(), loop.end(), 0);
  EXPECT_FALSE(cut_render_detail::flat_within(loop, x, 1e-4));
  std::vector<std::vector<int>> halves;
  ASSERT_TRUE(cut_render_detail::split_in_two_flat(loop, x, halves));
  ASSERT_EQ(halves.size(), 2U);
  for (const std::vector<int>& half : halves) EXPECT_TRUE(cut_render_detail::flat_within(half, x, 1e-4));
  // The chord is the junction: its ends are points 3 and 8, both halves run it (in opposite senses).
  EXPECT_EQ(std::min(halves[0].front(), halves[0].back()), 3);
  EXPECT_EQ(std::max(halves[0].front(), halves[0].back()), 8);
  EXPECT_EQ(halves[0].size() + halves[1].size(), loop.size() + 2);

  std::vector<Eigen::Vector3d> twisted;
  for (int k = 0; k < 16; ++k) {
    const double angle = 2.0 * M_PI * k / 16.0;
    twisted.emplace_back(3e-3 * std::cos(angle), 3e-3 * std::sin(angle), 1e-3 * std::sin(2.0 * angle));
  }
  std::vector<int> ring(twisted.size());
  std::iota(ring.begin(), ring.end(), 0);
  halves.clear();
  EXPECT_FALSE(cut_render_detail::split_in_two_flat(ring, twisted, halves));
  EXPECT_TRUE(halves.empty());
}

// A hole around the corner of a box on three cuts (the faces x = 0, y = 0, z = 0, runs of three
// points each, the walk having closed none of them) is peeled into the three faces: each run closed
// by the line between its ends, the nearest ends first. The peeled faces lie on their cut's plane;
// the faces together run each of the hole's edges once as the hole does and each line once each way.
// Line points (on no cut) and a short run between two runs of one cut belong to that cut's face.
// Peeled in the other orders (peel_again's), other faces come out, as closed.
TEST(PeelByCuts, PeelsAHoleIntoItsCutsFacesClosedByLines) {
  std::vector<Eigen::Vector3d> x{{4e-3, 1e-3, 0}, {4e-3, 4e-3, 0}, {1e-3, 4e-3, 0},    // z = 0: cut 2
                                 {0, 4e-3, 1e-3}, {0, 4e-3, 4e-3}, {0, 1.5e-3, 4e-3},  // x = 0: cut 0
                                 {1e-3, 0, 4e-3}, {4e-3, 0, 4e-3}, {4e-3, 0, 1e-3}};   // y = 0: cut 1
  std::vector<int> cut{2, 2, 2, 0, 0, 0, 1, 1, 1};
  const auto line_points = [&](int from, int to) {  // two points between, on no cut
    std::vector<int> points;
    for (const double s : {1.0 / 3.0, 2.0 / 3.0}) {
      x.push_back(x[static_cast<size_t>(from)] + s * (x[static_cast<size_t>(to)] - x[static_cast<size_t>(from)]));
      cut.push_back(-1);
      points.push_back(static_cast<int>(x.size()) - 1);
    }
    return points;
  };
  const auto cut_of = [&](int point) { return cut[static_cast<size_t>(point)]; };
  std::vector<int> hole(9);
  std::iota(hole.begin(), hole.end(), 0);
  std::vector<std::vector<int>> faces;
  ASSERT_TRUE(cut_render_detail::peel_by_cuts(hole, x, cut_of, line_points, faces));
  ASSERT_EQ(faces.size(), 3U);
  for (size_t f = 0; f + 1 < faces.size(); ++f) {  // the peeled ones: flat, on their own cut's plane
    const int face_cut = cut_of(faces[f].front());
    for (const int q : faces[f]) {
      if (cut_of(q) >= 0) {
        EXPECT_EQ(cut_of(q), face_cut) << "face " << f;
      }
      EXPECT_NEAR(x[static_cast<size_t>(q)][face_cut], 0.0, 1e-15) << "face " << f;  // the plane x_c = 0
    }
  }
  EXPECT_EQ(cut_of(faces[0].front()), 0);  // the nearest ends: (0, 4, 1) and (0, 1.5, 4) mm
  std::map<std::pair<int, int>, int> directed;
  for (const std::vector<int>& face : faces) {
    for (size_t i = 0; i < face.size(); ++i) ++directed[{face[i], face[(i + 1) % face.size()]}];
  }
  for (size_t i = 0; i < hole.size(); ++i) {
    const std::pair<int, int> edge{hole[i], hole[(i + 1) % hole.size()]};
    EXPECT_EQ(directed[edge], 1) << edge.first << "-" << edge.second;
    EXPECT_EQ(directed.count({edge.second, edge.first}), 0U);
  }
  for (const auto& [edge, uses] : directed) {
    EXPECT_EQ(uses, 1);
    if (edge.first >= 9 || edge.second >= 9) {
      EXPECT_EQ(directed.count({edge.second, edge.first}), 1U);  // a line: run both ways
    }
  }

  // Peeled in peel_again's orders: three faces again that run the hole's edges once each and their
  // lines once each way; the first is the run the order names (the farthest ends: cut 2 or 1, 4.2 mm
  // apart, not cut 0), and the faces after it need not lie on one plane (the lines join other runs).
  for (const cut_render_detail::PeelOrder order : cut_render_detail::PEEL_AGAIN_ORDERS) {
    std::vector<std::vector<int>> again;
    ASSERT_TRUE(cut_render_detail::peel_by_cuts(hole, x, cut_of, line_points, again, order));
    ASSERT_EQ(again.size(), 3U);
    std::map<std::pair<int, int>, int> runs;
    for (const std::vector<int>& face : again) {
      for (size_t i = 0; i < face.size(); ++i) ++runs[{face[i], face[(i + 1) % face.size()]}];
    }
    for (size_t i = 0; i < hole.size(); ++i) EXPECT_EQ((runs[{hole[i], hole[(i + 1) % hole.size()]}]), 1);
    for (const auto& [edge, uses] : runs) {
      EXPECT_EQ(uses, 1);
      if (edge.first >= 9 && edge.second >= 9) {
        EXPECT_EQ(runs.count({edge.second, edge.first}), 1U);
      }
    }
    for (const int q : again[0]) {
      if (cut_of(q) >= 0) {
        EXPECT_EQ(cut_of(q), cut_of(again[0].front()));
      }
    }
    if (order == cut_render_detail::PeelOrder::farthest_ends) {
      EXPECT_NE(cut_of(again[0].front()), 0);
    }
  }

  // Runs of cut 5 either side of line points and of a two-point run of cut 7 make one face of cut 5.
  std::vector<Eigen::Vector3d> y;
  for (int k = 0; k < 12; ++k) y.emplace_back(std::cos(k * M_PI / 6), std::sin(k * M_PI / 6), 0.0);
  const std::vector<int> cut5{5, 5, 5, -1, -1, 5, 5, 7, 7, 5, 6, 6};
  std::vector<int> ring(12);
  std::iota(ring.begin(), ring.end(), 0);
  faces.clear();
  std::vector<int> cuts5(cut5);
  const auto midpoint = [&](int from, int to) {
    y.push_back(0.5 * (y[static_cast<size_t>(from)] + y[static_cast<size_t>(to)]));
    cuts5.push_back(-1);
    return std::vector<int>{static_cast<int>(y.size()) - 1};
  };
  ASSERT_TRUE(cut_render_detail::peel_by_cuts(
      ring, y, [&](int q) { return cuts5[static_cast<size_t>(q)]; }, midpoint, faces));
  ASSERT_EQ(faces.size(), 2U);  // cut 6's run (the nearest ends), then the rest: one face of cut 5
  EXPECT_EQ(faces[0], (std::vector<int>{10, 11, 12}));
  EXPECT_EQ(faces[1].size(), ring.size() + 1);  // and the line's point

  // Four points on four cuts: no run to close by a line; nothing is added.
  faces.clear();
  const std::vector<int> four{0, 1, 2, 3};
  EXPECT_FALSE(cut_render_detail::peel_by_cuts(
      four, y, [](int q) { return q; }, midpoint, faces));
  EXPECT_TRUE(faces.empty());
}

TEST(FlatWithin, MeasuresTheLoopAgainstItsLeastSquaresPlaneWhateverItsTilt) {
  const Eigen::Vector3d normal = Eigen::Vector3d(1.0, 2.0, 2.0) / 3.0;
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  std::vector<Eigen::Vector3d> x;
  std::vector<int> loop;
  for (int k = 0; k < 12; ++k) {
    const double angle = 2.0 * M_PI * k / 12.0;
    // A 4 mm ring on a tilted plane, every other point 0.06 mm off it (+-0.03 mm about the fit).
    x.push_back(Eigen::Vector3d(0.01, 0.02, 0.03) + 0.002 * (std::cos(angle) * u + std::sin(angle) * v) +
                (k % 2 == 0 ? 6e-5 : 0.0) * normal);
    loop.push_back(k);
  }
  EXPECT_TRUE(cut_render_detail::flat_within(loop, x, 3.1e-5));
  EXPECT_FALSE(cut_render_detail::flat_within(loop, x, 2.9e-5));
}

}  // namespace
}  // namespace tissue

namespace tissue {
namespace {

// Closed shells under a cube of 0.1 mm that hold a cap are not drawn (drop_bubbles): of three tets'
// boundaries, one 1 mm across (kept), one 10 um across (dropped) and one 10 um across with a face
// missing (open: kept, its hole is counted, not hidden), the caps being each tet's last face.
TEST(DropBubbles, RemovesOnlyTinyClosedShellsThatHoldACap) {
  std::vector<Eigen::Vector3d> x;
  std::vector<std::array<int, 3>> skin, caps;
  const auto add_tet = [&](double size_m, double offset_m, bool closed) {
    const int o = static_cast<int>(x.size());
    x.emplace_back(offset_m, 0, 0);
    x.emplace_back(offset_m + size_m, 0, 0);
    x.emplace_back(offset_m, size_m, 0);
    x.emplace_back(offset_m, 0, size_m);
    skin.push_back({o, o + 2, o + 1});
    skin.push_back({o, o + 1, o + 3});
    if (closed) skin.push_back({o, o + 3, o + 2});
    caps.push_back({o + 1, o + 2, o + 3});
  };
  add_tet(1e-3, 0.0, true);
  add_tet(1e-5, 0.01, true);
  add_tet(1e-5, 0.02, false);
  std::vector<std::array<int, 3>> triangles = skin;
  triangles.insert(triangles.end(), caps.begin(), caps.end());
  cut_render_detail::BubbleScratch scratch;
  const size_t caps_left = cut_render_detail::drop_bubbles(triangles, skin.size(), x, scratch);
  EXPECT_EQ(caps_left, 2u);
  ASSERT_EQ(triangles.size(), 7u);  // the big tet's four, the open one's three
  for (const auto& t : triangles) EXPECT_TRUE(t[0] < 4 || t[0] >= 8) << "a triangle of the dropped tet";
}

}  // namespace
}  // namespace tissue
