// Several cuts per tet (issue 21): vertical strokes that cross, each through the full height of the
// specimen, made by the volume cutter on the specimen at rest and enriched stroke by stroke (a later
// stroke cuts the tets of an earlier one again).
// * The X: two strokes crossing in the middle of a cantilever beam leave four pieces.
// * The flap: three strokes that overshoot each other's ends cut a triangular prism out of the
//   frog's back.
// * The spiral (one stroke, two turns through a slab): checked against the spiral's own geometry
//   below, at its test.
// Each material point belongs to the region of the stroke lines it lies in (seen from above). For
// each specimen:
// * every uncut tet and every piece of a cut tet (its rest cell's centroid) is put in its region;
//   every real vertex of a piece lies in the piece's region; every ghost unknown is used by pieces of
//   one region only (the ghost keys join the pieces of a region, never two regions);
// * each region's mass is rho times its exact volume (the X: the prism over its polygon, by the
//   shoelace formula; the flap: every tet of the frog clipped by the three stroke planes), to 1e-9
//   relative; the total mass is unchanged;
// * each free region falls: its momentum along its translation, c_R^T M v, obeys backward Euler's
//   damped free fall of its mass exactly (c_R^T f_int = 0 for a detached region, c_R^T f_ext =
//   -M_R g; tests/unit/fem/test_xfem_beam.cpp), to 1e-8; the held region stays.
#include "core/collide/surface_bvh.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "core/surface_views.hpp"
#include "support/closed_surface.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <random>
#include <memory>
#include <string>
#include <vector>

namespace tissue {
namespace {

constexpr double DENSITY = 1000.0;
constexpr double GRAVITY = 9.81;
constexpr double ALPHA_PER_S = 1.0;
constexpr double STEP_S = 1e-3;

/// A stroke seen from above: a vertical blade from below to above the specimen, swept from `from`
/// to `to` (x, y).
struct Stroke {
  Eigen::Vector2d from;
  Eigen::Vector2d to;
};

/// Where the blade stands (x, y) at each cutter step of one session.
using BladePath = std::vector<Eigen::Vector2d>;

/// A straight stroke in 40 cutter steps.
BladePath straight_path(const Stroke& stroke) {
  constexpr int STEPS = 40;
  BladePath path;
  for (int n = 0; n <= STEPS; ++n) path.push_back(stroke.from + (stroke.to - stroke.from) * n / STEPS);
  return path;
}

std::vector<BladePath> straight_paths(const std::vector<Stroke>& strokes) {
  std::vector<BladePath> paths;
  for (const Stroke& stroke : strokes) paths.push_back(straight_path(stroke));
  return paths;
}

/// The vertical plane of a stroke, positive to the stroke's left.
CutPlane stroke_plane(const Stroke& stroke) {
  const Eigen::Vector2d d = stroke.to - stroke.from;
  const Eigen::Vector3d normal(-d.y(), d.x(), 0.0);
  return CutPlane{normal, normal.dot(Eigen::Vector3d(stroke.from.x(), stroke.from.y(), 0.0))};
}

using RegionOf = std::function<int(const Eigen::Vector3d&)>;

/// A specimen cut by strokes at rest, with nothing snapped and pieces as small as they come.
struct CutSpecimen {
  TetMesh mesh;
  SurfaceMesh surface = extract_surface(mesh);
  TetAdjacency adjacency = build_adjacency(mesh);
  DeformableBody body;
  DynamicState state;
  int recut_tets = 0;  ///< cuts of tets an earlier stroke cut
  /// Enrichments after which the tangent held fewer blocks than before: the blocks only retired cut
  /// tets used were dropped (RETIRED_SLOT_SHARE_TO_COMPACT), so the checks run on the compacted matrix.
  int compactions = 0;

  /// Each stroke: the vertical blade from z_below to z_above stands at the path's points. With
  /// `plunge`, it is first lowered into the body at the path's start from above it (its tip from
  /// z_above down to z_below in 10 steps) and lifted out at its end the same way, instead of standing
  /// in it at the start and being taken away where it ends (end_cut).
  CutSpecimen(TetMesh tet_mesh, std::vector<int> fixed, const std::vector<BladePath>& strokes, double z_below,
              double z_above, bool plunge = false)
      : mesh(std::move(tet_mesh)), body(mesh, settings(std::move(fixed))) {
    state.displacement_m = Eigen::VectorXd::Zero(body.dof_count());
    state.velocity_m_per_s = Eigen::VectorXd::Zero(body.dof_count());
    Eigen::VectorXd rest(3 * mesh.vertex_count());
    for (int v = 0; v < mesh.vertex_count(); ++v)
      rest.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<size_t>(v)];
    const SurfaceBvh bvh(surface.triangles, rest);
    CutterSettings exact;
    exact.vertex_snap_fraction = 0.0;
    exact.min_volume_fraction = SMALLEST_MIN_VOLUME_FRACTION;
    VolumeCutter cutter(mesh, adjacency, surface, exact);
    const double height_m = z_above - z_below;
    const auto blade_at = [&](const Eigen::Vector2d& at, double tip_z) {
      return Blade{Eigen::Vector3d(at.x(), at.y(), tip_z), Eigen::Vector3d(at.x(), at.y(), tip_z + height_m)};
    };
    const auto apply = [&] {
      for (const TetCut& cut : cutter.new_cuts()) recut_tets += body.cut_tet_index(cut.tet) >= 0 ? 1 : 0;
      if (cutter.new_cuts().empty()) return;
      const int blocks_before = body.tangent().nonzero_blocks();
      body.enrich(cutter.new_cuts(), state);
      compactions += body.tangent().nonzero_blocks() < blocks_before ? 1 : 0;
    };
    constexpr int PLUNGE_STEPS = 10;
    for (const BladePath& stroke : strokes) {
      std::vector<Blade> blades;
      for (int n = 0; plunge && n < PLUNGE_STEPS; ++n) blades.push_back(blade_at(stroke.front(), z_above - height_m * n / PLUNGE_STEPS));
      for (const Eigen::Vector2d& at : stroke) blades.push_back(blade_at(at, z_below));
      for (int n = 1; plunge && n <= PLUNGE_STEPS; ++n) blades.push_back(blade_at(stroke.back(), z_below + height_m * n / PLUNGE_STEPS));
      for (size_t n = 0; n < blades.size(); ++n) {
        cutter.step(blades[n == 0 ? 0 : n - 1], blades[n], rest, bvh);
        apply();
      }
      if (plunge) {
        EXPECT_FALSE(cutter.cutting()) << "the blade was lifted out";
      }
      cutter.end_cut(rest);  // the scalpel is taken away where it is: the next stroke is a new session
      apply();
    }
  }

  static BodySettings settings(std::vector<int> fixed) {
    BodySettings settings;
    settings.material = Material{5.0e5, 0.3, DENSITY};
    settings.damping = RayleighDamping{ALPHA_PER_S, 1e-3};
    settings.gravity_m_per_s2 = {0.0, 0.0, -GRAVITY};
    settings.fixed_vertices = std::move(fixed);
    return settings;
  }
};

/// Checks the pieces against the regions and their exact volumes, then lets the free regions fall
/// for `steps` steps (everything but `held`, whose vertices drop by less than `held_drop_m` on
/// average).
void expect_pieces_fall_as_regions(CutSpecimen& specimen, const RegionOf& region_of,
                                   const std::vector<double>& exact_volumes_m3, int held, int steps,
                                   double held_drop_m) {
  const DeformableBody& body = specimen.body;
  const TetMesh& mesh = specimen.mesh;
  const size_t regions = exact_volumes_m3.size();
  const auto vertex_region = [&](int v) { return region_of(mesh.rest_positions_m[static_cast<size_t>(v)]); };

  // Mass by region: uncut tets whole, cut tets piece by piece; each ghost in one region only.
  std::vector<double> mass_kg(regions, 0.0);
  for (int t = 0; t < mesh.tet_count(); ++t) {
    if (body.cut_tet_index(t) >= 0) continue;
    const auto x = mesh.rest_corners(t);
    mass_kg[static_cast<size_t>(region_of(0.25 * (x[0] + x[1] + x[2] + x[3])))] +=
        DENSITY * body.elasticity().rest(t).volume_m3;
  }
  std::map<int, int> ghost_region;  // block row -> region of the pieces using it
  int pieces = 0;
  for (int k = 0; k < static_cast<int>(body.cut_tets().size()); ++k) {
    if (body.retired(k)) continue;
    const int tet = body.cut_tets()[static_cast<size_t>(k)].cut.tet;
    EXPECT_EQ(body.cut_tet_index(tet), k);
    const CutTetGeometry& geometry = body.cut_geometry(k);
    for (int p = 0; p < static_cast<int>(body.xfem().piece_count(k)); ++p) {
      const ConvexPiece cell =
          piece_geometry(mesh.rest_corners(tet), geometry.cuts, geometry.pieces[static_cast<size_t>(p)].sides);
      const int region = region_of(cell.centroid_m());
      mass_kg[static_cast<size_t>(region)] += body.piece_mass_kg(k, p);
      ++pieces;
      const CutPiece& piece = body.xfem().piece(k, p);
      for (size_t j = 0; j < 4; ++j) {
        const int row = piece.ghost_row[j];
        if (row < 0) {
          EXPECT_EQ(vertex_region(mesh.tets[static_cast<size_t>(tet)][j]), region) << "a real vertex of tet " << tet;
          continue;
        }
        const auto [it, added] = ghost_region.emplace(row, region);
        EXPECT_EQ(it->second, region) << "ghost row " << row << " joins two regions";
      }
    }
  }
  EXPECT_GT(pieces, 2 * body.cut_tet_count());  // some tets hold more than two pieces
  double total_kg = 0.0;
  double exact_total_m3 = 0.0;
  for (size_t r = 0; r < regions; ++r) {
    EXPECT_NEAR(mass_kg[r], DENSITY * exact_volumes_m3[r], 1e-9 * DENSITY * exact_volumes_m3[r]) << "region " << r;
    total_kg += mass_kg[r];
    exact_total_m3 += exact_volumes_m3[r];
  }
  EXPECT_NEAR(total_kg, DENSITY * exact_total_m3, 1e-12 * total_kg);
  EXPECT_NEAR(body.total_mass_kg(), total_kg, 1e-12 * total_kg);

  // Each region's translation along z: u of its vertices and the ghosts its pieces use (a ghost is a
  // copy with its own displacement).
  std::vector<Eigen::VectorXd> c_z(regions, Eigen::VectorXd::Zero(body.dof_count()));
  for (size_t r = 0; r < regions; ++r) {
    Eigen::VectorXd& c = c_z[r];
    for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
      if (vertex_region(body.dofs().row_vertex[static_cast<size_t>(row)]) == static_cast<int>(r)) c(3 * row + 2) = 1.0;
    }
    for (const EnrichedDof& dof : body.enriched_dofs()) {
      if (!ghost_region.contains(dof.row)) continue;  // used by retired cut tets only
      if (ghost_region[dof.row] == static_cast<int>(r)) c(3 * dof.row + 2) = 1.0;
    }
    if (static_cast<int>(r) != held) {
      EXPECT_NEAR(c.dot(body.external_force_n()), -mass_kg[r] * GRAVITY, 1e-9 * mass_kg[r] * GRAVITY) << "region " << r;
    }
  }

  // Backward Euler: each free region's momentum follows Pi_{n+1} = (Pi_n - h M g) / (1 + h alpha).
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  std::vector<double> momentum(regions, 0.0);
  std::vector<double> worst_error(regions, 0.0);
  for (int n = 0; n < steps; ++n) {
    integrator.step(specimen.body, specimen.state, STEP_S);
    for (size_t r = 0; r < regions; ++r) {
      if (static_cast<int>(r) == held) continue;
      momentum[r] = (momentum[r] - STEP_S * mass_kg[r] * GRAVITY) / (1.0 + STEP_S * ALPHA_PER_S);
      const double measured = c_z[r].dot(body.mass_kg().cwiseProduct(specimen.state.velocity_m_per_s));
      worst_error[r] =
          std::max(worst_error[r], std::abs(measured - momentum[r]) / (mass_kg[r] * GRAVITY * STEP_S * steps));
    }
  }
  ASSERT_TRUE(specimen.state.displacement_m.allFinite());
  for (size_t r = 0; r < regions; ++r) {
    if (static_cast<int>(r) != held) {
      EXPECT_LT(worst_error[r], 1e-8) << "region " << r;
    }
  }
  // Where the pieces went: the free ones fell (at least half the ideal drop), the held one sags.
  std::vector<double> drop_m(regions, 0.0);
  std::vector<int> count(regions, 0);
  Eigen::VectorXd x;
  body.positions(specimen.state.displacement_m, x);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const auto r = static_cast<size_t>(vertex_region(v));
    drop_m[r] += mesh.rest_positions_m[static_cast<size_t>(v)].z() - x(3 * v + 2);
    ++count[r];
  }
  const double ideal_m = 0.5 * GRAVITY * (steps * STEP_S) * (steps * STEP_S);
  for (size_t r = 0; r < regions; ++r) {
    if (count[r] == 0) continue;  // a region may hold no vertex
    const double mean = drop_m[r] / count[r];
    if (static_cast<int>(r) == held) {
      EXPECT_LT(std::abs(mean), held_drop_m);
    } else {
      EXPECT_GT(mean, 0.5 * ideal_m) << "region " << r;
    }
  }
}

// --- the X through a beam ------------------------------------------------------------------------

constexpr double BEAM_LENGTH_M = 0.1;
constexpr double BEAM_SIDE_M = 0.02;
// The two cut lines seen from above cross at CROSSING, at slopes dx/dy = +-SLANT.
const Eigen::Vector2d CROSSING(0.0503, 0.0101);
constexpr double SLANT = 0.6;

double line_x(int line, double y) { return CROSSING.x() + (line == 0 ? SLANT : -SLANT) * (y - CROSSING.y()); }

// Which side of each line a point (seen from above) lies on: the region, 0..3.
int x_region(const Eigen::Vector3d& p) {
  const bool right_of_first = p.x() > line_x(0, p.y());
  const bool right_of_second = p.x() > line_x(1, p.y());
  return (right_of_first ? 1 : 0) + (right_of_second ? 2 : 0);
}

double shoelace_m2(const std::vector<Eigen::Vector2d>& polygon) {
  double twice = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * std::abs(twice);
}

// The beam held at x = 0 and cut through along both lines of the X (each stroke past both sides).
CutSpecimen x_cut_beam() {
  const double w = BEAM_SIDE_M;
  const auto stroke = [&](int line) {
    return Stroke{{line_x(line, -0.005), -0.005}, {line_x(line, w + 0.005), w + 0.005}};
  };
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  std::vector<int> fixed = vertices_at_minimum(mesh, 0, 1e-6);
  return CutSpecimen(std::move(mesh), std::move(fixed), straight_paths({stroke(0), stroke(1)}), -0.02, 0.04);
}

TEST(CrossingCuts, AnXCutLeavesFourPiecesOfTheExactVolumesAndTheThreeFreeOnesFall) {
  const double w = BEAM_SIDE_M;
  CutSpecimen beam = x_cut_beam();
  ASSERT_GT(beam.recut_tets, 0);  // the second stroke cut tets of the first again

  // The exact volumes: prisms over the regions' polygons.
  const Eigen::Vector2d bottom_first(line_x(0, 0.0), 0.0), top_first(line_x(0, w), w);
  const Eigen::Vector2d bottom_second(line_x(1, 0.0), 0.0), top_second(line_x(1, w), w);
  std::vector<double> volumes_m3(4, 0.0);
  volumes_m3[static_cast<size_t>(x_region({0.0, 0.5 * w, 0.0}))] =
      shoelace_m2({{0.0, 0.0}, bottom_first, CROSSING, top_second, {0.0, w}}) * w;
  volumes_m3[static_cast<size_t>(x_region({BEAM_LENGTH_M, 0.5 * w, 0.0}))] =
      shoelace_m2({bottom_second, {BEAM_LENGTH_M, 0.0}, {BEAM_LENGTH_M, w}, top_first, CROSSING}) * w;
  volumes_m3[static_cast<size_t>(x_region({CROSSING.x(), 0.0, 0.0}))] =
      shoelace_m2({bottom_first, bottom_second, CROSSING}) * w;
  volumes_m3[static_cast<size_t>(x_region({CROSSING.x(), w, 0.0}))] =
      shoelace_m2({top_second, CROSSING, top_first}) * w;
  expect_pieces_fall_as_regions(beam, x_region, volumes_m3, x_region({0.0, 0.5 * w, 0.0}), 150, 5e-3);
}

// The drawn tet skin after the X cut (issue 43): welded across the tets cut twice too, a closed
// 2-manifold per piece, every edge (by its pair of point ids) with one triangle each way.
TEST(CrossingCuts, AnXCutDrawsAClosedSurfacePerPiece) {
  CutSpecimen beam = x_cut_beam();
  ASSERT_GT(beam.recut_tets, 0);
  SurfaceViews views(beam.body, false, nullptr);
  views.add_cut_tets(beam.body, beam.state.displacement_m, 0);
  std::vector<std::array<int, 3>> triangles;
  views.for_each_drawn_triangle(beam.body, beam.state.displacement_m,
                                [&](const std::array<int, 3>& t) { triangles.push_back(t); });
  EXPECT_EQ(test_support::check_surface(triangles, static_cast<int>(views.positions_m().size() / 3)).open_edges, 0);
}

// The faces of the cut tets the second stroke replaced collapse to a point and leave the surface
// BVH's tree (issue 41: after 30 + 30 careless strokes they were a third of its leaves, refitted at
// every cutting step): out of the tree are exactly the cut faces of zero area.
TEST(CrossingCuts, TheRetiredFacesOfAnXLeaveTheSurfaceBvh) {
  CutSpecimen beam = x_cut_beam();
  ASSERT_GT(beam.recut_tets, 0);
  SurfaceViews views(beam.body, true, nullptr);
  views.add_cut_tets(beam.body, beam.state.displacement_m, 0);
  const SurfaceBvh& bvh = views.bvh().fitted();
  const Eigen::VectorXd& x = views.positions_m();
  int out = 0;
  for (int id = 0; id < bvh.triangle_count(); ++id) {
    const std::array<int, 3>& t = bvh.triangle(id);
    const Eigen::Vector3d a = x.segment<3>(3 * t[0]);
    const double area_m2 = 0.5 * (x.segment<3>(3 * t[1]) - a).cross(x.segment<3>(3 * t[2]) - a).norm();
    EXPECT_EQ(bvh.in_tree(id), area_m2 > 0.0) << "triangle " << id << " of area " << area_m2 << " m^2";
    out += bvh.in_tree(id) ? 0 : 1;
  }
  std::printf("%d of %d triangles out of the tree (%d tets cut twice)\n", out, bvh.triangle_count(), beam.recut_tets);
  EXPECT_GT(out, 0);
}

// --- the flap out of the frog's back -------------------------------------------------------------

/// Three strokes along the sides of a triangle on the frog's back, each running past the corners at
/// its ends by `overshoot_m` (0: from corner to corner, the strokes meeting at the corners); with
/// `plunge`, the blade is lowered in at a stroke's start and lifted out at its end.
void expect_triangular_flap_falls(double overshoot_m, bool plunge = false) {
  TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  const std::array<Eigen::Vector2d, 3> corner{Eigen::Vector2d(-0.0213, -0.0117), Eigen::Vector2d(0.0161, -0.0129),
                                              Eigen::Vector2d(-0.0019, 0.0147)};
  std::vector<Stroke> strokes;
  std::array<CutPlane, 3> inside{};  // positive inside the triangle
  const Eigen::Vector2d centre = (corner[0] + corner[1] + corner[2]) / 3.0;
  for (size_t k = 0; k < 3; ++k) {
    const Eigen::Vector2d& a = corner[k];
    const Eigen::Vector2d& b = corner[(k + 1) % 3];
    const Eigen::Vector2d along = (b - a).normalized();
    strokes.push_back(Stroke{a - overshoot_m * along, b + overshoot_m * along});
    inside[k] = stroke_plane(strokes.back());
    if (inside[k].signed_distance(Eigen::Vector3d(centre.x(), centre.y(), 0.0)) < 0.0) {
      inside[k] = CutPlane{-inside[k].normal, -inside[k].offset};
    }
  }
  const RegionOf flap_region = [inside](const Eigen::Vector3d& p) {
    for (const CutPlane& plane : inside) {
      if (plane.signed_distance(p) <= 0.0) return 0;
    }
    return 1;
  };
  // The prism's exact volume: every tet of the frog clipped by the three planes.
  double prism_m3 = 0.0;
  double frog_m3 = 0.0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    ConvexPiece piece = ConvexPiece::tet(mesh.rest_corners(t));
    frog_m3 += piece.volume_m3();
    for (const CutPlane& plane : inside) piece = piece.clipped(plane, true, 0.0);
    prism_m3 += piece.volume_m3();
  }
  ASSERT_GT(prism_m3, 0.05 * frog_m3);  // a flap worth the name
  // Held at both ends (the 15 % of its length at either end: hind legs and head).
  std::vector<int> fixed = vertices_at_minimum(mesh, 0, 0.15);
  double x_max = mesh.rest_positions_m[0].x(), x_min = x_max;
  for (const Eigen::Vector3d& p : mesh.rest_positions_m) {
    x_max = std::max(x_max, p.x());
    x_min = std::min(x_min, p.x());
  }
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<size_t>(v)].x() > x_max - 0.15 * (x_max - x_min)) fixed.push_back(v);
  }
  CutSpecimen frog(std::move(mesh), std::move(fixed), straight_paths(strokes), -0.03, 0.06, plunge);
  ASSERT_GT(frog.recut_tets, 0);  // the corners' tets were cut twice
  // The frog sags between its held ends; the flap falls away from it.
  expect_pieces_fall_as_regions(frog, flap_region, {frog_m3 - prism_m3, prism_m3}, 0, 40, 5e-3);
}

TEST(CrossingCuts, ThreeStrokesOvershootingTheCornersCutATriangularFlapThatFallsWithThePrismsMass) {
  expect_triangular_flap_falls(0.02);  // about two tets past each corner
}

// Where a stroke ends at an earlier cut inside a tet (a T junction) or starts at its end (the
// corner), the tets up to the blade are cut: a flap needs no overshoot.
TEST(CrossingCuts, ThreeStrokesMeetingAtTheCornersCutATriangularFlapThatFallsWithThePrismsMass) {
  expect_triangular_flap_falls(0.0);
}

// The same strokes as a surgeon makes them: the blade lowered into the back at one corner, drawn to
// the next and lifted out there (the stroke ends when the blade leaves the body).
TEST(CrossingCuts, ThreeStrokesPlungedAndLiftedAtTheCornersCutATriangularFlapThatFalls) {
  expect_triangular_flap_falls(0.0, true);
}

// --- the retired cut tets' blocks ----------------------------------------------------------------

// The frog hatched by 4 + 4 full-height strokes (tets cut up to three times, their earlier cut tets
// retired): dropping the blocks only retired cut tets used (DeformableBody::drop_retired_blocks, which
// enrich() does itself past RETIRED_SLOT_SHARE_TO_COMPACT) leaves the internal forces bitwise and the
// tangent's product to round-off as they were (the dropped blocks were zeros); packing the rows then
// (issue 41, item 3) leaves both bitwise as they were; and every XFEM block left is one a live cut
// tet uses.
TEST(CrossingCuts, DroppingTheRetiredCutTetsBlocksChangesNeitherTheForcesNorTheProduct) {
  std::vector<Stroke> strokes;
  for (int k = 0; k < 4; ++k) {
    const double x = -0.02 + 0.04 * k / 3.0 + 0.0003;
    const double y = -0.03 + 0.06 * k / 3.0 + 0.0007;
    strokes.push_back(Stroke{{x, -0.09}, {x + 0.003, 0.09}});
    strokes.push_back(Stroke{{-0.12, y}, {0.12, y - 0.002}});
  }
  TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  std::vector<int> fixed = vertices_at_minimum(mesh, 2, 0.25);
  CutSpecimen frog(std::move(mesh), std::move(fixed), straight_paths(strokes), -0.03, 0.06);
  ASSERT_GT(frog.recut_tets, 50);
  DeformableBody& body = frog.body;

  std::mt19937 rng(21);
  std::normal_distribution<double> normal;
  Eigen::VectorXd u(body.dof_count()), x(body.dof_count());
  for (Eigen::Index i = 0; i < u.size(); ++i) {
    u(i) = 1e-4 * normal(rng);
    x(i) = normal(rng);
  }
  Eigen::VectorXd force_before, force_after, product_before, product_after;
  // Both evaluations from the same rotation warm starts (an evaluate moves them).
  DeformableBody::Rotations warm_starts;
  body.save_rotations(warm_starts);
  body.evaluate(u, force_before, /*update_tangent=*/true);
  body.tangent().multiply(x, product_before);
  const int blocks_before = body.tangent().nonzero_blocks();

  ASSERT_TRUE(body.drop_retired_blocks());
  EXPECT_LT(body.tangent().nonzero_blocks(), blocks_before);
  body.restore_rotations(warm_starts);
  body.evaluate(u, force_after, /*update_tangent=*/true);
  body.tangent().multiply(x, product_after);
  EXPECT_TRUE((force_after.array() == force_before.array()).all());
  // The product to round-off: the multiply kernel sums a row's blocks in an order that depends on how
  // many there are.
  EXPECT_LT((product_after - product_before).cwiseAbs().maxCoeff(), 1e-13 * product_before.cwiseAbs().maxCoeff());
  std::printf("dropped %d of %d blocks; the product moved by %.3g of its largest entry\n",
              blocks_before - body.tangent().nonzero_blocks(), blocks_before,
              (product_after - product_before).cwiseAbs().maxCoeff() / product_before.cwiseAbs().maxCoeff());
  EXPECT_FALSE(body.drop_retired_blocks());  // nothing left to drop

  // The rows packed (what the drop does by itself once their room passes ROW_ROOM_PER_BLOCK_TO_PACK
  // times their blocks): the forces and the product bitwise as they were, the room given back.
  ASSERT_GT(body.tangent().row_room(), body.tangent().nonzero_blocks());
  ASSERT_TRUE(body.drop_retired_blocks(DeformableBody::PackRows::always));
  EXPECT_EQ(body.tangent().row_room(), body.tangent().nonzero_blocks());
  Eigen::VectorXd force_packed, product_packed;
  body.restore_rotations(warm_starts);
  body.evaluate(u, force_packed, /*update_tangent=*/true);
  body.tangent().multiply(x, product_packed);
  EXPECT_TRUE((force_packed.array() == force_before.array()).all());
  EXPECT_TRUE((product_packed.array() == product_after.array()).all());
  EXPECT_FALSE(body.drop_retired_blocks(DeformableBody::PackRows::always));  // packed already

  // Every block with a ghost row or column is one a live cut tet uses.
  const BlockSparseMatrix& tangent = body.tangent();
  std::vector<char> used(static_cast<size_t>(tangent.slot_capacity()), 0);
  for (int k = 0; k < body.xfem().cut_tet_count(); ++k) {
    if (body.retired(k)) continue;
    for (const int slot : const_cast<XfemElasticity&>(body.xfem()).slots(k)) {
      if (slot >= 0) used[static_cast<size_t>(slot)] = 1;
    }
  }
  const int u_rows = body.dofs().free_vertex_count();
  for (int row = 0; row < tangent.block_rows(); ++row) {
    for (int slot = tangent.row_begin(row); slot < tangent.row_begin(row) + tangent.row_size(row); ++slot) {
      const int column = tangent.slot_column(slot);
      if ((row >= u_rows || column >= u_rows) && column != row) {
        EXPECT_TRUE(used[static_cast<size_t>(slot)] != 0) << "block (" << row << ", " << column << ")";
      }
    }
  }
}

// --- a T junction in a slab ----------------------------------------------------------------------

constexpr double SLAB_EDGE_M = 0.005;  // the slabs' cubes

// A 10 x 10 x 1 cm slab of 5 mm cubes held along two edges (x = 0 and y = 0). The first stroke runs
// along y = T_FIRST_Y from inside the slab out through its edge x = 0.1; the second comes in
// through the edge y = 0.1 along x = T_SECOND_X and ends at the first (a T junction): on it, or as
// a hand would, past it by less than a tet (into the tets beyond it, whose extra cut joins no two
// regions). The corner beyond both (x > T_SECOND_X, y > T_FIRST_Y) is then cut free on both its
// inner sides and falls. (A stroke that stops short of the earlier cut leaves the material between
// attached where it lies in tets the blade did not go into: a bridge that is there.)
constexpr double T_FIRST_Y = 0.0512;
constexpr double T_SECOND_X = 0.0613;

int t_region(const Eigen::Vector3d& p) { return p.x() > T_SECOND_X && p.y() > T_FIRST_Y ? 1 : 0; }

TEST(CrossingCuts, AStrokeEndingAtAnEarlierCutCutsTheTetsUpToItAndFreesTheCornerBeyond) {
  for (const double end_past_m : {0.0, 1e-3, 3e-3}) {
    SCOPED_TRACE("the second stroke ends " + std::to_string(1e3 * end_past_m) + " mm past the first");
    TetMesh mesh = make_box_mesh(20, 20, 2, SLAB_EDGE_M);
    std::vector<int> fixed = vertices_at_minimum(mesh, 0, 1e-6);
    for (const int v : vertices_at_minimum(mesh, 1, 1e-6)) {
      if (std::find(fixed.begin(), fixed.end(), v) == fixed.end()) fixed.push_back(v);
    }
    const std::vector<Stroke> strokes{Stroke{{0.0313, T_FIRST_Y}, {0.105, T_FIRST_Y}},
                                      Stroke{{T_SECOND_X, 0.105}, {T_SECOND_X, T_FIRST_Y - end_past_m}}};
    CutSpecimen slab(std::move(mesh), std::move(fixed), straight_paths(strokes), -0.01, 0.02);
    ASSERT_GT(slab.recut_tets, 0);  // the junction's tets were cut by both strokes
    const double slab_m3 = 0.1 * 0.1 * 0.01;
    const double corner_m3 = (0.1 - T_SECOND_X) * (0.1 - T_FIRST_Y) * 0.01;
    // The slab held along two edges sags by less than a millimetre on average in 40 ms.
    expect_pieces_fall_as_regions(slab, t_region, {slab_m3 - corner_m3, corner_m3}, 0, 40, 1e-3);
  }
}

// --- the spiral through a slab --------------------------------------------------------------------

// The dissertation's figure 7.1: a spiral stroke, where one global Heaviside leaves a vertex between
// two turns on both sides of the same cut. An Archimedean spiral r = b theta about its centre, two
// turns from `first_rad` to `first_rad` + 4 pi (both ends on one ray).
struct Spiral {
  Eigen::Vector2d centre{0.0501, 0.0502};
  double pitch_m = 0.0;  ///< 2 pi b: how far apart the turns are
  double first_rad = 0.0;

  [[nodiscard]] double last_rad() const { return first_rad + 4.0 * M_PI; }
  [[nodiscard]] double radius_m(double theta) const { return pitch_m / (2.0 * M_PI) * theta; }

  /// The blade's path, about 1 mm a step.
  [[nodiscard]] BladePath path() const {
    BladePath points;
    for (double theta = first_rad; theta <= last_rad(); theta += 1e-3 / radius_m(theta)) {
      points.push_back(centre + radius_m(theta) * Eigen::Vector2d(std::cos(theta), std::sin(theta)));
    }
    return points;
  }

  /// A tet's cut is one plane: where the spiral bends, it passes the tet's vertices at up to the
  /// sagitta of its longest edge (a face diagonal of the slab's cubes) over the turn's radius from
  /// the curve, on either side (an edge may even dip across the curve and back). A vertex closer than
  /// this to the curve may be on either side.
  [[nodiscard]] static double side_tolerance_m(double radius_m) {
    return std::pow(std::sqrt(2.0) * SLAB_EDGE_M, 2) / (8.0 * radius_m);
  }

  /// How many turns of the spiral lie between the centre and `p` on the ray through `p` (seen from
  /// above): 0 inside the inner turn, 1 between the turns, 2 outside; -1 within the side tolerance
  /// of a turn. Two points of different bands are separated by the cut wherever both ends of the
  /// spiral are far.
  [[nodiscard]] int band(const Eigen::Vector3d& p) const {
    const Eigen::Vector2d d = p.head<2>() - centre;
    double phi = std::atan2(d.y(), d.x());
    if (phi < 0.0) phi += 2.0 * M_PI;
    int band = 0;
    for (double theta = phi; theta <= last_rad(); theta += 2.0 * M_PI) {
      if (theta < first_rad) continue;
      if (std::abs(radius_m(theta) - d.norm()) < side_tolerance_m(radius_m(theta))) return -1;
      if (radius_m(theta) < d.norm()) ++band;
    }
    return band;
  }

  /// Distance (seen from above) from `p` to the ray on which the spiral starts and ends.
  [[nodiscard]] double distance_to_ends_ray_m(const Eigen::Vector3d& p) const {
    const Eigen::Vector2d ray(std::cos(first_rad), std::sin(first_rad));
    const Eigen::Vector2d d = p.head<2>() - centre;
    const double along = std::max(0.0, d.dot(ray));
    return (d - along * ray).norm();
  }
};

/// What cutting a slab along a spiral did, judged away from the spiral's two ends.
struct SpiralCut {
  int cut_tets = 0;              ///< judged tets cut
  int twice_cut_tets = 0;        ///< judged tets cut by both turns
  int recut_tets = 0;            ///< cuts of a tet cut before (CutSpecimen::recut_tets)
  int ghost_uses = 0;            ///< ghost rows used by judged pieces
  int between_turns = 0;         ///< vertices between the turns with ghosts beyond both
};

/// A 10 x 10 x 1 cm slab of 5 mm cubes cut at rest along `spiral` in one session. Checks: the mass
/// is unchanged; each judged tet (its vertices at least three cube edges from the ends' ray, none
/// within the side tolerance of a turn) carries one cut per turn between its vertices (the span of
/// their bands); no vertex on the wrong side: a piece's real vertices lie in one band (the piece's),
/// a ghost of vertex v is used by pieces of one band only, not v's.
SpiralCut cut_slab_along(const Spiral& spiral) {
  TetMesh mesh = make_box_mesh(20, 20, 2, SLAB_EDGE_M);
  double slab_m3 = 0.0;
  for (int t = 0; t < mesh.tet_count(); ++t) slab_m3 += ConvexPiece::tet(mesh.rest_corners(t)).volume_m3();
  CutSpecimen slab(std::move(mesh), {}, {spiral.path()}, -0.01, 0.02);
  const DeformableBody& body = slab.body;
  const TetMesh& slab_mesh = slab.mesh;
  EXPECT_NEAR(body.total_mass_kg(), DENSITY * slab_m3, 1e-12 * DENSITY * slab_m3);
  SpiralCut result;
  result.recut_tets = slab.recut_tets;

  const auto vertex_band = [&](int v) { return spiral.band(slab_mesh.rest_positions_m[static_cast<size_t>(v)]); };
  const auto judged = [&](int tet) {
    for (int v : slab_mesh.tets[static_cast<size_t>(tet)]) {
      if (spiral.distance_to_ends_ray_m(slab_mesh.rest_positions_m[static_cast<size_t>(v)]) < 3.0 * SLAB_EDGE_M) {
        return false;
      }
    }
    return true;
  };
  for (int t = 0; t < slab_mesh.tet_count(); ++t) {
    if (!judged(t)) continue;
    const auto& tet = slab_mesh.tets[static_cast<size_t>(t)];
    std::array<int, 4> bands{};
    std::transform(tet.begin(), tet.end(), bands.begin(), vertex_band);
    if (*std::min_element(bands.begin(), bands.end()) < 0) continue;
    const int turns_between = *std::max_element(bands.begin(), bands.end()) - *std::min_element(bands.begin(), bands.end());
    const int k = body.cut_tet_index(t);
    const int cuts = k < 0 ? 0 : static_cast<int>(body.cut_geometry(k).cuts.size());
    EXPECT_EQ(cuts, turns_between) << "tet " << t;
    result.cut_tets += cuts > 0 ? 1 : 0;
    result.twice_cut_tets += cuts > 1 ? 1 : 0;
  }

  std::map<int, int> ghost_band;  // block row -> band of the pieces using it
  std::map<int, std::vector<int>> vertex_ghost_bands;
  for (int k = 0; k < static_cast<int>(body.cut_tets().size()); ++k) {
    const int tet = body.cut_tets()[static_cast<size_t>(k)].cut.tet;
    if (body.retired(k) || !judged(tet)) continue;
    for (int p = 0; p < static_cast<int>(body.xfem().piece_count(k)); ++p) {
      const CutPiece& piece = body.xfem().piece(k, p);
      int band = -1;
      for (size_t j = 0; j < 4; ++j) {
        if (piece.ghost_row[j] >= 0) continue;
        const int real_band = vertex_band(slab_mesh.tets[static_cast<size_t>(tet)][j]);
        if (real_band < 0) continue;
        if (band < 0) band = real_band;
        EXPECT_EQ(real_band, band) << "a real vertex of tet " << tet << " on the wrong side of the spiral";
      }
      if (band < 0) continue;  // its real vertices lie on the curve, or it has none (between two cuts)
      for (size_t j = 0; j < 4; ++j) {
        const int row = piece.ghost_row[j];
        if (row < 0) continue;
        const int v = slab_mesh.tets[static_cast<size_t>(tet)][j];
        EXPECT_NE(vertex_band(v), band) << "a ghost of vertex " << v << " on the vertex's own side";
        ++result.ghost_uses;
        const auto [it, added] = ghost_band.emplace(row, band);
        EXPECT_EQ(it->second, band) << "ghost row " << row << " of vertex " << v << " joins two bands";
        if (added) vertex_ghost_bands[v].push_back(band);
      }
    }
  }
  for (const auto& [v, bands] : vertex_ghost_bands) {
    result.between_turns += (vertex_band(v) == 1 && std::count(bands.begin(), bands.end(), 0) > 0 &&
                             std::count(bands.begin(), bands.end(), 2) > 0)
                                ? 1
                                : 0;
  }
  std::printf("spiral of pitch %.1f mm: %d judged tets cut, %d of them twice, %d ghost uses judged, %d vertices "
              "between the turns with ghosts beyond both\n",
              1e3 * spiral.pitch_m, result.cut_tets, result.twice_cut_tets, result.ghost_uses, result.between_turns);
  return result;
}

TEST(CrossingCuts, ASpiralStrokeCutsAlongItsWholePathWithEveryPieceOnItsSideOfTheTurns) {
  // A pitch of 2 cube edges: no tet (longest edge, a face diagonal: sqrt 2 cube edges) meets both
  // turns; the stars of some vertices between the turns meet both.
  const SpiralCut cut = cut_slab_along(Spiral{.pitch_m = 2.0 * SLAB_EDGE_M, .first_rad = 2.0 * M_PI + 0.3});
  EXPECT_GT(cut.cut_tets, 200);
  EXPECT_EQ(cut.recut_tets, 0);  // no tet meets both turns
  EXPECT_GT(cut.between_turns, 0);
  EXPECT_GT(cut.ghost_uses, 1000);
}

TEST(CrossingCuts, ASpiralTighterThanATetCutsTheTetsBetweenItsTurnsOncePerTurn) {
  // A pitch of 0.8 cube edges, from 16 to 24 mm about the centre: one session crosses many tets
  // twice, a turn apart, and cuts each of them twice.
  const SpiralCut cut = cut_slab_along(Spiral{.pitch_m = 0.8 * SLAB_EDGE_M, .first_rad = 12.0 * M_PI + 0.3});
  EXPECT_GT(cut.twice_cut_tets, 50);
  EXPECT_GE(cut.recut_tets, cut.twice_cut_tets);
  EXPECT_GT(cut.between_turns, 0);
}

}  // namespace
}  // namespace tissue
