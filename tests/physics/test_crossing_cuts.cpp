// Several cuts per tet (issue 21): two vertical cuts that cross in the middle of a cantilever beam,
// an X seen from above, each through its full height and width, made by the volume cutter on the
// beam at rest and enriched between them (the second cuts the first one's tets again).
// * Four pieces: each material point of the beam belongs to the quadrant of the two planes it lies
//   in. Every uncut tet and every piece of a cut tet (its rest cell's centroid) is put in its
//   quadrant; every ghost unknown is used by pieces of one quadrant only (the ghost keys join the
//   pieces of a region, never two regions).
// * Each piece's mass is rho times the exact volume of its region of the beam: the prism over the
//   region's polygon seen from above (shoelace), to 1e-9 relative; the total mass is unchanged.
// * The three free pieces fall: for each, the momentum along its translation c_R^T M v obeys
//   backward Euler's damped free fall of its mass exactly (c_R^T f_int = 0 for a detached region,
//   c_R^T f_ext = -M_R g; tests/unit/xfem/test_xfem_beam.cpp), while the clamped piece stays.
#include "core/collide/surface_bvh.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/topology.hpp"
#include "core/tissue.hpp"
#include "core/tissue_snapshot_io.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

namespace tissue {
namespace {

constexpr double LENGTH_M = 0.1;
constexpr double SIDE_M = 0.02;
constexpr double DENSITY = 1000.0;
constexpr double GRAVITY = 9.81;
constexpr double ALPHA_PER_S = 1.0;
constexpr double STEP_S = 1e-3;

// The two cut lines seen from above cross at CROSSING, at slopes dx/dy = +-SLANT.
const Eigen::Vector2d CROSSING(0.0503, 0.0101);
constexpr double SLANT = 0.6;

double line_x(int line, double y) { return CROSSING.x() + (line == 0 ? SLANT : -SLANT) * (y - CROSSING.y()); }

// Which side of each line a point (seen from above) lies on: the region, 0..3.
int region_of(const Eigen::Vector3d& p) {
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

// The exact volume of each region: the prism over its polygon.
std::array<double, 4> region_volumes_m3() {
  const Eigen::Vector2d bottom_first(line_x(0, 0.0), 0.0), top_first(line_x(0, SIDE_M), SIDE_M);
  const Eigen::Vector2d bottom_second(line_x(1, 0.0), 0.0), top_second(line_x(1, SIDE_M), SIDE_M);
  // Left of both lines: the clamped end; right of both: the free end; the wedges between them.
  const std::vector<Eigen::Vector2d> left{{0.0, 0.0}, bottom_first, CROSSING, top_second, {0.0, SIDE_M}};
  const std::vector<Eigen::Vector2d> right{bottom_second, {LENGTH_M, 0.0}, {LENGTH_M, SIDE_M}, top_first, CROSSING};
  const std::vector<Eigen::Vector2d> bottom{bottom_first, bottom_second, CROSSING};  // right of the first only
  const std::vector<Eigen::Vector2d> top{top_second, CROSSING, top_first};            // right of the second only
  std::array<double, 4> volumes{};
  volumes[region_of({0.0, 0.5 * SIDE_M, 0.0})] = shoelace_m2(left) * SIDE_M;
  volumes[region_of({LENGTH_M, 0.5 * SIDE_M, 0.0})] = shoelace_m2(right) * SIDE_M;
  volumes[region_of({CROSSING.x(), 0.0, 0.0})] = shoelace_m2(bottom) * SIDE_M;
  volumes[region_of({CROSSING.x(), SIDE_M, 0.0})] = shoelace_m2(top) * SIDE_M;
  return volumes;
}

// A vertical blade swept along cut line `line` across the beam's width, as the cutter's steps.
std::vector<Blade> stroke(int line) {
  std::vector<Blade> path;
  constexpr int STEPS = 30;
  for (int n = 0; n <= STEPS; ++n) {
    const double y = -0.005 + (SIDE_M + 0.01) * n / STEPS;
    path.push_back(Blade{Eigen::Vector3d(line_x(line, y), y, -0.02), Eigen::Vector3d(line_x(line, y), y, 0.04)});
  }
  return path;
}

struct CutBeam {
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  SurfaceMesh surface = extract_surface(mesh);
  TetAdjacency adjacency = build_adjacency(mesh);
  DeformableBody body{mesh, settings(mesh)};
  DynamicState state;
  std::vector<int> recut_tets;

  static BodySettings settings(const TetMesh& mesh) {
    BodySettings settings;
    settings.material = Material{5.0e5, 0.3, DENSITY};
    settings.damping = RayleighDamping{ALPHA_PER_S, 1e-3};
    settings.gravity_m_per_s2 = {0.0, 0.0, -GRAVITY};
    settings.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
    return settings;
  }

  CutBeam() {
    state.displacement_m = Eigen::VectorXd::Zero(body.dof_count());
    state.velocity_m_per_s = Eigen::VectorXd::Zero(body.dof_count());
    Eigen::VectorXd rest(3 * mesh.vertex_count());
    for (int v = 0; v < mesh.vertex_count(); ++v) rest.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<size_t>(v)];
    const SurfaceBvh bvh(surface.triangles, rest);
    CutterSettings exact;  // crossings as computed, and pieces as small as they come
    exact.vertex_snap_fraction = 0.0;
    exact.min_volume_fraction = SMALLEST_MIN_VOLUME_FRACTION;
    VolumeCutter cutter(mesh, adjacency, surface, exact);
    for (const int line : {0, 1}) {
      const std::vector<Blade> path = stroke(line);
      for (size_t i = 0; i < path.size(); ++i) {
        cutter.step(path[i == 0 ? 0 : i - 1], path[i], rest, bvh);
        for (const TetCut& cut : cutter.new_cuts()) {
          if (body.cut_tet_index(cut.tet) >= 0) recut_tets.push_back(cut.tet);
        }
        if (!cutter.new_cuts().empty()) body.enrich(cutter.new_cuts(), state);
      }
      EXPECT_FALSE(cutter.cutting());
    }
  }

  [[nodiscard]] std::array<Eigen::Vector3d, 4> rest_corners(int tet) const {
    const Tet& v = mesh.tets[static_cast<size_t>(tet)];
    return {mesh.rest_positions_m[static_cast<size_t>(v[0])], mesh.rest_positions_m[static_cast<size_t>(v[1])],
            mesh.rest_positions_m[static_cast<size_t>(v[2])], mesh.rest_positions_m[static_cast<size_t>(v[3])]};
  }
  // The region of piece p of (live) cut tet k, by its rest cell's centroid.
  [[nodiscard]] int piece_region(int k, int p) const {
    const CutTetGeometry& geometry = body.cut_geometry(k);
    const ConvexPiece cell = piece_geometry(rest_corners(body.cut_tets()[static_cast<size_t>(k)].cut.tet), geometry.cuts,
                                            geometry.pieces[static_cast<size_t>(p)].sides);
    return region_of(cell.centroid_m());
  }
};

TEST(CrossingCuts, AnXCutLeavesFourPiecesOfTheExactVolumesAndTheThreeFreeOnesFall) {
  CutBeam beam;
  const DeformableBody& body = beam.body;
  ASSERT_FALSE(beam.recut_tets.empty());  // the second stroke cut tets of the first again

  // Mass by region: uncut tets whole, cut tets piece by piece; each ghost in one region only.
  std::array<double, 4> mass_kg{};
  for (int t = 0; t < beam.mesh.tet_count(); ++t) {
    if (body.cut_tet_index(t) >= 0) continue;
    const auto x = beam.rest_corners(t);
    mass_kg[static_cast<size_t>(region_of(0.25 * (x[0] + x[1] + x[2] + x[3])))] +=
        DENSITY * body.elasticity().rest(t).volume_m3;
  }
  std::map<int, int> ghost_region;  // block row -> region of the pieces using it
  std::map<int, double> ghost_sign;
  int pieces = 0;
  for (int k = 0; k < static_cast<int>(body.cut_tets().size()); ++k) {
    if (body.retired(k)) continue;
    const int tet = body.cut_tets()[static_cast<size_t>(k)].cut.tet;
    EXPECT_EQ(body.cut_tet_index(tet), k);
    for (int p = 0; p < static_cast<int>(body.xfem().piece_count(k)); ++p) {
      const int region = beam.piece_region(k, p);
      mass_kg[static_cast<size_t>(region)] += body.piece_mass_kg(k, p);
      ++pieces;
      const CutPiece& piece = body.xfem().piece(k, p);
      for (size_t j = 0; j < 4; ++j) {
        const int row = piece.ghost_row[j];
        const int vertex = beam.mesh.tets[static_cast<size_t>(tet)][j];
        if (row < 0) {  // a real vertex lies in its piece's region
          EXPECT_EQ(region_of(beam.mesh.rest_positions_m[static_cast<size_t>(vertex)]), region) << "tet " << tet;
          continue;
        }
        const auto [it, added] = ghost_region.emplace(row, region);
        EXPECT_EQ(it->second, region) << "ghost row " << row << " joins two regions";
        ghost_sign[row] = piece.ghost_sign[j];
      }
    }
  }
  EXPECT_GT(pieces, 2 * body.cut_tet_count());  // some tets hold more than two pieces
  const std::array<double, 4> volumes_m3 = region_volumes_m3();
  double total_kg = 0.0;
  for (int r = 0; r < 4; ++r) {
    EXPECT_NEAR(mass_kg[static_cast<size_t>(r)], DENSITY * volumes_m3[static_cast<size_t>(r)],
                1e-9 * DENSITY * volumes_m3[static_cast<size_t>(r)])
        << "region " << r;
    total_kg += mass_kg[static_cast<size_t>(r)];
  }
  EXPECT_NEAR(total_kg, DENSITY * LENGTH_M * SIDE_M * SIDE_M, 1e-12 * total_kg);
  EXPECT_DOUBLE_EQ(body.total_mass_kg(), DENSITY * LENGTH_M * SIDE_M * SIDE_M);

  // Each region's translation along z: u of its vertices, its ghosts of vertices elsewhere (+sign),
  // and the ghosts of its vertices in other regions' pieces (-sign, so that they stay).
  const int clamped = region_of({0.0, 0.5 * SIDE_M, 0.0});
  std::array<Eigen::VectorXd, 4> c_z;
  for (int r = 0; r < 4; ++r) {
    c_z[static_cast<size_t>(r)] = Eigen::VectorXd::Zero(body.dof_count());
    Eigen::VectorXd& c = c_z[static_cast<size_t>(r)];
    for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
      const int vertex = body.dofs().row_vertex[static_cast<size_t>(row)];
      if (region_of(beam.mesh.rest_positions_m[static_cast<size_t>(vertex)]) == r) c(3 * row + 2) = 1.0;
    }
    for (const EnrichedDof& dof : body.enriched_dofs()) {
      if (!ghost_region.contains(dof.row)) continue;  // used by retired cut tets only
      const bool piece_here = ghost_region[dof.row] == r;
      const bool vertex_here = region_of(beam.mesh.rest_positions_m[static_cast<size_t>(dof.vertex)]) == r;
      if (piece_here != vertex_here) c(3 * dof.row + 2) = (piece_here ? 1.0 : -1.0) * ghost_sign[dof.row];
    }
    if (r != clamped) {
      EXPECT_NEAR(c.dot(body.external_force_n()), -mass_kg[static_cast<size_t>(r)] * GRAVITY,
                  1e-9 * mass_kg[static_cast<size_t>(r)] * GRAVITY)
          << "region " << r;
    }
  }

  // Backward Euler: each free region's momentum follows Pi_{n+1} = (Pi_n - h M g) / (1 + h alpha).
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  std::array<double, 4> momentum{};
  std::array<double, 4> worst_error{};
  const int steps = 150;
  for (int n = 0; n < steps; ++n) {
    integrator.step(beam.body, beam.state, STEP_S);
    for (int r = 0; r < 4; ++r) {
      if (r == clamped) continue;
      const auto rr = static_cast<size_t>(r);
      momentum[rr] = (momentum[rr] - STEP_S * mass_kg[rr] * GRAVITY) / (1.0 + STEP_S * ALPHA_PER_S);
      const double measured = c_z[rr].dot(body.mass_kg().cwiseProduct(beam.state.velocity_m_per_s));
      worst_error[rr] = std::max(worst_error[rr], std::abs(measured - momentum[rr]) / (mass_kg[rr] * GRAVITY * STEP_S * steps));
    }
  }
  ASSERT_TRUE(beam.state.displacement_m.allFinite());
  for (int r = 0; r < 4; ++r) {
    if (r == clamped) continue;
    EXPECT_LT(worst_error[static_cast<size_t>(r)], 1e-8) << "region " << r;
  }
  // Where the pieces went: the free ones fell (at least half the ideal 0.11 m), the clamped one sags
  // by millimetres.
  std::array<double, 4> drop_m{};
  std::array<int, 4> count{};
  Eigen::VectorXd x;
  body.positions(beam.state.displacement_m, x);
  for (int v = 0; v < beam.mesh.vertex_count(); ++v) {
    const Eigen::Vector3d& rest = beam.mesh.rest_positions_m[static_cast<size_t>(v)];
    drop_m[static_cast<size_t>(region_of(rest))] += rest.z() - x(3 * v + 2);
    ++count[static_cast<size_t>(region_of(rest))];
  }
  const double ideal_m = 0.5 * GRAVITY * (steps * STEP_S) * (steps * STEP_S);
  for (int r = 0; r < 4; ++r) {
    if (count[static_cast<size_t>(r)] == 0) continue;  // a wedge may hold no vertex
    const double mean = drop_m[static_cast<size_t>(r)] / count[static_cast<size_t>(r)];
    if (r == clamped) {
      EXPECT_LT(std::abs(mean), 5e-3);
    } else {
      EXPECT_GT(mean, 0.5 * ideal_m) << "region " << r;
    }
  }
}

}  // namespace
}  // namespace tissue
