// Many random straight strokes through still bodies (issue 41): planes at random, through a vertex,
// through an edge, and within 1e-12 of an edge from a vertex, drawn across the whole body in 1 to
// 40 steps. Judged against the plane itself, computed here: each vertex's side is the sign of its
// distance from the plane (within its snap distance, vertex_snap_fraction of its shortest edge, it
// lies on the blade and counts above), and a tet is cut exactly when its vertices have both sides
// (except where the plane only grazes the body, along a surface edge or at a vertex: nothing to
// separate there, and a tet may stay whole).
// So no tet holds the two sides together (no bridge), no tet on one side is cut, and every cut is
// finite. The suite runs 300 strokes; TISSUE_FUZZ_STROKES=10000 runs a nightly-size run.
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "cut/cutter_reference.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <random>
#include <string>

namespace tissue::test_cut {
namespace {

int stroke_count() {
  const char* text = std::getenv("TISSUE_FUZZ_STROKES");
  return text != nullptr ? std::max(1, std::atoi(text)) : 300;
}

/// Each vertex's snap distance, computed from the edges (the cutter's rule, written out again).
std::vector<double> snap_distances_m(const Body& body, double fraction) {
  std::vector<double> snap(body.mesh.rest_positions_m.size(), std::numeric_limits<double>::infinity());
  for (const auto& ends : body.adjacency.edges) {
    const double length_m = (body.x(ends[1]) - body.x(ends[0])).norm();
    for (const int v : ends) snap[at(v)] = std::min(snap[at(v)], fraction * length_m);
  }
  return snap;
}

struct Plane {
  Eigen::Vector3d point;
  Eigen::Vector3d normal;  ///< unit
  std::string kind;
};

Plane random_plane(const Body& body, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  const auto unit = [&] { return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized(); };
  std::uniform_int_distribution<int> kind(0, 3);
  std::uniform_int_distribution<int> pick_vertex(0, body.mesh.vertex_count() - 1);
  std::uniform_int_distribution<int> pick_edge(0, static_cast<int>(body.adjacency.edges.size()) - 1);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const Eigen::Vector3d centre = 0.5 * (body.lower() + body.upper());
  switch (kind(rng)) {
    case 0: {  // anywhere through the body's middle half
      const Eigen::Vector3d offset = (body.upper() - body.lower()).cwiseProduct(
          Eigen::Vector3d(uniform(rng) - 0.5, uniform(rng) - 0.5, uniform(rng) - 0.5) * 0.5);
      return {centre + offset, unit(), "random"};
    }
    case 1:
      return {body.x(pick_vertex(rng)), unit(), "through a vertex"};
    case 2: {  // containing an edge: the normal is orthogonal to it
      const auto& ends = body.adjacency.edges[at(pick_edge(rng))];
      const Eigen::Vector3d along = (body.x(ends[1]) - body.x(ends[0])).normalized();
      const Eigen::Vector3d n = unit();
      return {body.x(ends[0]), (n - n.dot(along) * along).normalized(), "through an edge"};
    }
    default: {  // through a point 1e-12 of an edge's length from its first vertex
      const auto& ends = body.adjacency.edges[at(pick_edge(rng))];
      return {body.x(ends[0]) + 1e-12 * (body.x(ends[1]) - body.x(ends[0])), unit(), "1e-12 from a vertex"};
    }
  }
}

void fuzz(const Body& body, int strokes, unsigned seed) {
  const SurfaceBvh bvh = body.make_bvh();
  const CutterSettings settings;
  const std::vector<double> snap_m = snap_distances_m(body, settings.vertex_snap_fraction);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pick_steps(1, 40);
  std::normal_distribution<double> normal;
  const double size = body.size_m();
  int cut_total = 0;
  for (int s = 0; s < strokes; ++s) {
    const Plane plane = random_plane(body, rng);
    // The blade lies in the plane (three body sizes long, through its point) and moves within it
    // from a body size before the point to one after: it passes the whole body.
    const Eigen::Vector3d random(normal(rng), normal(rng), normal(rng));
    const Eigen::Vector3d along = (random - random.dot(plane.normal) * plane.normal).normalized();
    const Eigen::Vector3d motion = plane.normal.cross(along);
    const auto blade_at = [&](double offset) {
      const Eigen::Vector3d centre = plane.point + offset * size * motion;
      return Blade{centre - 1.5 * size * along, centre + 1.5 * size * along};
    };
    const int steps = pick_steps(rng);
    VolumeCutter cutter(body.mesh, body.adjacency, body.surface, settings);
    const std::vector<Blade> path = linear_path(blade_at(-1.0), blade_at(1.0), steps);
    for (std::size_t i = 0; i < path.size(); ++i) {
      cutter.step(path[i == 0 ? 0 : i - 1], path[i], body.positions_m, bvh);
      for (const TetCut& cut : cutter.new_cuts()) {
        ASSERT_TRUE(std::isfinite(cut.volume_fraction_above)) << plane.kind << ", stroke " << s;
        for (const double r : cut.edge_ratio) ASSERT_TRUE(std::isfinite(r)) << plane.kind << ", stroke " << s;
      }
    }
    ASSERT_FALSE(cutter.cutting()) << "the blade left the body";
    // The sweep's normal is (handle - tip) x motion = along x (normal x along) = normal: above is +normal.
    const auto distance_m = [&](int v) { return plane.normal.dot(body.x(v) - plane.point); };
    // A vertex on the blade with material strictly above it (a tet around it with a vertex above its
    // snap distance): a tet below that keeps it whole would join the two sides there.
    std::vector<char> joins_above(body.mesh.rest_positions_m.size(), 0);
    for (int t = 0; t < body.mesh.tet_count(); ++t) {
      const Tet& tet = body.mesh.tets[at(t)];
      if (std::none_of(tet.begin(), tet.end(), [&](int v) { return distance_m(v) > snap_m[at(v)]; })) continue;
      for (const int v : tet) joins_above[at(v)] = 1;
    }
    for (int t = 0; t < body.mesh.tet_count(); ++t) {
      bool below = false;
      bool above = false;
      bool grazing = true;  // above only through vertices on the blade with nothing above them
      for (const int v : body.mesh.tets[at(t)]) {
        const double d = distance_m(v);
        below |= d < -snap_m[at(v)];
        above |= d >= -snap_m[at(v)];
        if (d >= -snap_m[at(v)] && (d > snap_m[at(v)] || joins_above[at(v)] != 0)) grazing = false;
      }
      const bool cut = cutter.cut_count(t) > 0;  // a fresh cutter: any session (the frog is not convex)
      // A blade that touches the body only along an edge or at a vertex on its surface (the plane
      // grazes it) separates nothing: those tets may stay whole, or be cut (slivers of nothing on
      // the far side) by each of the one-step sessions the grazing blade makes.
      if (below && above && grazing) continue;
      std::string detail;
      for (const int v : body.mesh.tets[at(t)]) {
        const auto side = cutter.vertex_side(v);
        detail += " v" + std::to_string(v) + " d/snap " + std::to_string(plane.normal.dot(body.x(v) - plane.point) / snap_m[at(v)]) +
                  " side " + (side ? std::to_string(*side) : std::string("?"));
      }
      ASSERT_EQ(cut, below && above) << (cut ? "a tet on one side was cut" : "a tet across the plane was left whole")
                                     << ": tet " << t << ", plane " << plane.kind << ", stroke " << s << " in " << steps
                                     << " steps;" << detail;
      EXPECT_LE(cutter.cut_count(t), 1) << "one stroke cut tet " << t << " twice, plane " << plane.kind << ", stroke " << s;
      cut_total += cut;
    }
  }
  EXPECT_GT(cut_total, strokes);  // the strokes did cut
}

TEST(StrokeFuzz, EveryStraightStrokeThroughABoxCutsExactlyTheTetsAcrossItsPlane) {
  fuzz(Body(make_box_mesh(4, 3, 3, 0.01)), stroke_count(), 41u);
}

TEST(StrokeFuzz, EveryStraightStrokeThroughTheFrogCutsExactlyTheTetsAcrossItsPlane) {
  fuzz(Body(read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg")), std::max(1, stroke_count() / 10), 4141u);
}

}  // namespace
}  // namespace tissue::test_cut
