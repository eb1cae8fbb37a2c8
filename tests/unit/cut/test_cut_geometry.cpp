// One cut tet: which crossing patterns cut it completely, which side is above, and the exact
// volume fractions (planes at known positions, a non-planar 2-2 split against a hand-made
// decomposition into tets, parts adding up to the whole, clamping near a vertex, degenerate cuts).
#include "core/cut/cut_geometry.hpp"
#include "core/fem/convex_piece.hpp"
#include "core/mesh/tet_mesh.hpp"
#include "core/mesh/topology.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

namespace tissue {
namespace {

using Points = std::array<Eigen::Vector3d, 4>;

/// The unit corner tet: x0 at the origin, x_k = e_k (positive orientation, volume 1/6).
Points unit_tet() {
  return {Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
}

/// The same tet under a fixed affine map with positive determinant: volume fractions are affine invariant.
Points sheared_tet() {
  Eigen::Matrix3d map;
  map << 2.0, 0.3, -0.4, 0.1, 1.5, 0.2, -0.2, 0.4, 0.8;
  const Eigen::Vector3d shift(0.5, -1.0, 2.0);
  Points x = unit_tet();
  for (auto& p : x) p = map * p + shift;
  return x;
}

int local_edge(int i, int j) {
  for (int k = 0; k < 6; ++k) {
    if (TET_EDGES[static_cast<std::size_t>(k)][0] == i && TET_EDGES[static_cast<std::size_t>(k)][1] == j) return k;
  }
  return -1;
}

/// Records a crossing of edge {i, j} (i < j) at ratio r from i, with `upper` the end above the cut.
void cross(TetEdgeCrossings& crossings, int i, int j, double r, int upper) {
  const auto k = static_cast<std::size_t>(local_edge(i, j));
  crossings.ratio[k] = r;
  crossings.upper_end[k] = static_cast<std::int8_t>(upper == j ? 1 : -1);
}

/// The crossings a plane {f(x) = 0} makes on the tet, upper end = the vertex with f > 0.
TetEdgeCrossings plane_crossings(const Points& x, const Eigen::Vector3d& normal, double offset) {
  TetEdgeCrossings crossings;
  for (int k = 0; k < 6; ++k) {
    const auto& edge = TET_EDGES[static_cast<std::size_t>(k)];
    const double fi = normal.dot(x[static_cast<std::size_t>(edge[0])]) - offset;
    const double fj = normal.dot(x[static_cast<std::size_t>(edge[1])]) - offset;
    if ((fi < 0.0) == (fj < 0.0)) continue;
    cross(crossings, edge[0], edge[1], fi / (fi - fj), fj > 0.0 ? edge[1] : edge[0]);
  }
  return crossings;
}

/// Fraction of the tet where the linear function with vertex values f exceeds 0, in closed form:
/// sum_i max(f_i, 0)^3 / prod_{j != i} (f_i - f_j) (the tail of the B-spline with knots f_i);
/// needs distinct values.
double fraction_above_plane(const std::array<double, 4>& f) {
  double fraction = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    if (f[i] <= 0.0) continue;
    double denominator = 1.0;
    for (std::size_t j = 0; j < 4; ++j) {
      if (j != i) denominator *= f[i] - f[j];
    }
    fraction += f[i] * f[i] * f[i] / denominator;
  }
  return fraction;
}

constexpr double MIN_FRACTION = 1e-3;
constexpr double NO_SNAP = 0.0;
// Volumes are sums of a few products of O(1) coordinates: round-off is a few ulps of 1.
constexpr double EXACT = 1e-13;

TEST(CutGeometry, PlaneParallelToAFaceCutsOffTheCubeOfItsHeight) {
  for (const Points& x : {unit_tet(), sheared_tet()}) {
    for (const double t : {0.05, 0.3, 0.5, 0.77, 0.95}) {
      // Cut near vertex 0 at fraction t of each edge from it: the corner part is t^3 of the tet.
      TetEdgeCrossings near_0;
      cross(near_0, 0, 1, t, 0);
      cross(near_0, 0, 2, t, 0);
      cross(near_0, 0, 3, t, 0);
      const auto cut = classify_tet_cut(x, near_0, NO_SNAP, 1e-9);
      ASSERT_TRUE(cut);
      EXPECT_EQ(cut->side, (std::array<std::int8_t, 4>{1, -1, -1, -1}));
      EXPECT_NEAR(cut->volume_fraction_above, t * t * t, EXACT);
      EXPECT_DOUBLE_EQ(cut->edge_ratio[0], t);
      EXPECT_EQ(cut->edge_ratio[3], -1.0);  // edge 1-2 lies below the cut

      // The same around vertex 3 with vertex 3 below: the part above is the rest.
      TetEdgeCrossings near_3;
      cross(near_3, 0, 3, 1.0 - t, 0);
      cross(near_3, 1, 3, 1.0 - t, 1);
      cross(near_3, 2, 3, 1.0 - t, 2);
      const auto cut3 = classify_tet_cut(x, near_3, NO_SNAP, 1e-9);
      ASSERT_TRUE(cut3);
      EXPECT_EQ(cut3->side, (std::array<std::int8_t, 4>{1, 1, 1, -1}));
      EXPECT_NEAR(cut3->volume_fraction_above, 1.0 - t * t * t, EXACT);
    }
  }
}

TEST(CutGeometry, PlanarTwoTwoSplitHasTheIntegratedVolume) {
  // Plane x + y = c splits {0, 3} from {1, 2}; the part x + y > c has volume fraction
  // 6 * int_c^1 s (1 - s) ds = 1 - 3 c^2 + 2 c^3.
  for (const double c : {0.1, 0.25, 0.5, 0.8}) {
    TetEdgeCrossings crossings;
    cross(crossings, 0, 1, c, 1);
    cross(crossings, 0, 2, c, 2);
    cross(crossings, 1, 3, 1.0 - c, 1);
    cross(crossings, 2, 3, 1.0 - c, 2);
    for (const Points& x : {unit_tet(), sheared_tet()}) {
      const auto cut = classify_tet_cut(x, crossings, NO_SNAP, MIN_FRACTION);
      ASSERT_TRUE(cut);
      EXPECT_EQ(cut->side, (std::array<std::int8_t, 4>{-1, 1, 1, -1}));
      EXPECT_NEAR(cut->volume_fraction_above, 1.0 - 3.0 * c * c + 2.0 * c * c * c, EXACT);
    }
  }
}

TEST(CutGeometry, RandomPlanesGiveTheClosedFormFraction) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> uniform(-0.3, 0.3);
  int checked = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const Points x = trial % 2 == 0 ? unit_tet() : sheared_tet();
    const Eigen::Vector3d n = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d centroid = 0.25 * (x[0] + x[1] + x[2] + x[3]);
    const double offset = n.dot(centroid) + uniform(rng);
    std::array<double, 4> f{};
    for (std::size_t v = 0; v < 4; ++v) f[v] = n.dot(x[v]) - offset;
    const auto cut = classify_tet_cut(x, plane_crossings(x, n, offset), NO_SNAP, 1e-9);
    const bool plane_crosses =
        *std::min_element(f.begin(), f.end()) < 0.0 && *std::max_element(f.begin(), f.end()) > 0.0;
    ASSERT_EQ(cut.has_value(), plane_crosses);
    if (!cut) continue;
    for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(cut->side[v], f[v] > 0.0 ? 1 : -1);
    // The closed form loses digits when vertex values nearly coincide: 1e-9 is far above that
    // for these well-separated random values, and far below any real error.
    EXPECT_NEAR(cut->volume_fraction_above, fraction_above_plane(f), 1e-9);
    ++checked;
  }
  EXPECT_GT(checked, 300);
}

/// Signed volume of a tet from four points.
double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return signed_tet_volume(a, b, c, d);
}

TEST(CutGeometry, NonPlanarTwoTwoSplitIsTheWedgeCutAlongTheShorterDiagonal) {
  // {0, 1} against {2, 3}: cut points a on 0-2, b on 0-3, c on 1-2, d on 1-3 are not coplanar.
  // The part holding 0 and 1 is the wedge with ends (x0, a, b) and (x1, c, d).
  const Points x = unit_tet();
  const double ra = 0.5, rb = 0.5, rc = 0.2, rd = 0.7;
  TetEdgeCrossings crossings;
  cross(crossings, 0, 2, ra, 2);
  cross(crossings, 0, 3, rb, 3);
  cross(crossings, 1, 2, rc, 2);
  cross(crossings, 1, 3, rd, 3);
  const Eigen::Vector3d a = (1 - ra) * x[0] + ra * x[2];
  const Eigen::Vector3d b = (1 - rb) * x[0] + rb * x[3];
  const Eigen::Vector3d c = (1 - rc) * x[1] + rc * x[2];
  const Eigen::Vector3d d = (1 - rd) * x[1] + rd * x[3];
  // The prism (x0, a, b | x1, c, d) as three tets; the split of the top quad (a, b, d, c) is the
  // one the tets share; the lateral quads lie in tet faces, so their diagonals do not matter.
  const double along_ad = std::abs(tet_volume(x[0], a, b, d)) + std::abs(tet_volume(x[0], a, c, d)) +
                          std::abs(tet_volume(x[0], x[1], c, d));
  const double along_bc = std::abs(tet_volume(x[0], b, a, c)) + std::abs(tet_volume(x[0], b, d, c)) +
                          std::abs(tet_volume(x[0], x[1], d, c));
  const double volume = 1.0 / 6.0;
  ASSERT_GT(std::abs(along_ad - along_bc), 1e-3 * volume);  // the diagonal matters here
  const bool ad_shorter = (a - d).norm() < (b - c).norm();
  const double expected_below = (ad_shorter ? along_ad : along_bc) / volume;

  const auto cut = classify_tet_cut(x, crossings, NO_SNAP, MIN_FRACTION);
  ASSERT_TRUE(cut);
  EXPECT_EQ(cut->side, (std::array<std::int8_t, 4>{-1, -1, 1, 1}));
  EXPECT_NEAR(1.0 - cut->volume_fraction_above, expected_below, EXACT);
}

TEST(CutGeometry, PartsAddUpToTheTet) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ratio(0.01, 0.99);
  const Points x = sheared_tet();
  const double volume = signed_tet_volume(x[0], x[1], x[2], x[3]);
  for (const unsigned group : {0b0001u, 0b0010u, 0b0100u, 0b1000u, 0b0011u, 0b0101u, 0b1001u}) {
    for (int trial = 0; trial < 50; ++trial) {
      std::array<Eigen::Vector3d, 6> points;
      for (std::size_t k = 0; k < 6; ++k) {
        const double r = ratio(rng);
        points[k] =
            (1 - r) * x[static_cast<std::size_t>(TET_EDGES[k][0])] + r * x[static_cast<std::size_t>(TET_EDGES[k][1])];
      }
      const double part = part_volume(x, group, points);
      const double rest = part_volume(x, ~group & 0b1111u, points);
      EXPECT_GT(part, 0.0);
      EXPECT_GT(rest, 0.0);
      EXPECT_NEAR((part + rest) / volume, 1.0, EXACT);
    }
  }
}

TEST(CutGeometry, FractionIsClampedToTheSmallestAllowed) {
  // A corner of 1e-6 of the volume (0.01 along each edge, beyond the 1e-3 snap) is cut off.
  TetEdgeCrossings crossings;
  cross(crossings, 0, 1, 0.01, 0);
  cross(crossings, 0, 2, 0.01, 0);
  cross(crossings, 0, 3, 0.01, 0);
  for (const double min_fraction : {1e-3, 1e-2, 0.4}) {
    const auto cut = classify_tet_cut(unit_tet(), crossings, 1e-3, min_fraction);
    ASSERT_TRUE(cut);
    EXPECT_EQ(cut->volume_fraction_above, min_fraction);
  }
  // Below the clamp nothing changes.
  const auto loose = classify_tet_cut(unit_tet(), crossings, 1e-3, 1e-7);
  ASSERT_TRUE(loose);
  EXPECT_NEAR(loose->volume_fraction_above, 1e-6, EXACT);
  // Upper end clamped when the corner lies below.
  TetEdgeCrossings below;
  cross(below, 0, 1, 0.01, 1);
  cross(below, 0, 2, 0.01, 2);
  cross(below, 0, 3, 0.01, 3);
  const auto cut = classify_tet_cut(unit_tet(), below, 1e-3, 1e-3);
  ASSERT_TRUE(cut);
  EXPECT_EQ(cut->side, (std::array<std::int8_t, 4>{-1, 1, 1, 1}));
  EXPECT_EQ(cut->volume_fraction_above, 1.0 - 1e-3);
}

TEST(CutGeometry, CutWithinTheSnapDistanceOfAVertexOnlyTouchesIt) {
  // Within 1e-3 of vertex 0 on all three edges: the cut passes through vertex 0 and cuts nothing.
  TetEdgeCrossings crossings;
  cross(crossings, 0, 1, 5e-4, 0);
  cross(crossings, 0, 2, 5e-4, 0);
  cross(crossings, 0, 3, 5e-4, 0);
  EXPECT_FALSE(classify_tet_cut(unit_tet(), crossings, 1e-3, MIN_FRACTION));
  // Without snapping it is a (clamped) cut.
  EXPECT_TRUE(classify_tet_cut(unit_tet(), crossings, NO_SNAP, MIN_FRACTION));
}

TEST(CutGeometry, CutThroughAVertexAndTwoEdges) {
  // Through vertex 0 (edge 0-1 crossed at its end) and across edges 1-2, 1-3: vertex 1 is cut
  // off with the tet (x1, x0, p12, p13), fraction r12 * r13 (ratios from vertex 1).
  const double r12 = 0.4, r13 = 0.7;
  TetEdgeCrossings crossings;
  cross(crossings, 0, 1, 0.0, 1);
  cross(crossings, 1, 2, r12, 1);
  cross(crossings, 1, 3, r13, 1);
  const auto cut = classify_tet_cut(sheared_tet(), crossings, 1e-3, MIN_FRACTION);
  ASSERT_TRUE(cut);
  EXPECT_EQ(cut->side[1], 1);
  EXPECT_EQ(cut->side[2], -1);
  EXPECT_EQ(cut->side[3], -1);
  EXPECT_NEAR(cut->volume_fraction_above, r12 * r13, EXACT);
  EXPECT_EQ(cut->edge_ratio[static_cast<std::size_t>(local_edge(0, 1))], 0.0);
}

TEST(CutGeometry, CutAlongAFaceDetachesTheOppositeVertexWithAClampedFraction) {
  // The sweep contains face (0, 1, 2): edges to vertex 3 are crossed at their other end.
  TetEdgeCrossings crossings;
  cross(crossings, 0, 3, 0.0, 3);
  cross(crossings, 1, 3, 0.0, 3);
  cross(crossings, 2, 3, 0.0, 3);
  const auto cut = classify_tet_cut(sheared_tet(), crossings, 1e-3, MIN_FRACTION);
  ASSERT_TRUE(cut);
  EXPECT_EQ(cut->side, (std::array<std::int8_t, 4>{-1, -1, -1, 1}));
  EXPECT_EQ(cut->volume_fraction_above, 1.0 - MIN_FRACTION);  // all of the tet lies above
}

TEST(CutGeometry, TouchingAnEdgeOrAVertexOrACrossingInsideAPartDoesNotCut) {
  TetEdgeCrossings along_edge;  // sweep contains edge 0-1: edges to 2 and 3 crossed at 0 and 1
  cross(along_edge, 0, 2, 0.0, 2);
  cross(along_edge, 0, 3, 0.0, 3);
  cross(along_edge, 1, 2, 0.0, 2);
  cross(along_edge, 1, 3, 0.0, 3);
  EXPECT_FALSE(classify_tet_cut(unit_tet(), along_edge, 1e-3, MIN_FRACTION));

  TetEdgeCrossings at_vertex;
  cross(at_vertex, 0, 1, 0.0, 1);
  cross(at_vertex, 0, 2, 0.0, 2);
  cross(at_vertex, 0, 3, 0.0, 3);
  EXPECT_FALSE(classify_tet_cut(unit_tet(), at_vertex, 1e-3, MIN_FRACTION));

  TetEdgeCrossings partial;  // two edges: the cut has entered but not left the tet
  cross(partial, 0, 1, 0.3, 1);
  cross(partial, 0, 2, 0.3, 2);
  EXPECT_FALSE(classify_tet_cut(unit_tet(), partial, 1e-3, MIN_FRACTION));

  TetEdgeCrossings folded = partial;  // 1-3 split at vertex 0 plus a crossing of edge 1-2
  cross(folded, 0, 3, 0.3, 3);
  cross(folded, 1, 2, 0.5, 2);
  EXPECT_FALSE(classify_tet_cut(unit_tet(), folded, 1e-3, MIN_FRACTION));

  EXPECT_FALSE(classify_tet_cut(unit_tet(), TetEdgeCrossings{}, 1e-3, MIN_FRACTION));
}

// --- cut_from_sides: the cut of a tet whose vertices' sides were decided (issue 41) ---------------

// Random tets cut by random planes through them: with the sides of the vertices and the plane's
// crossings of the edges between them, the volume fraction above is the plane's clip of the tet
// (ConvexPiece, an independent computation) to round-off, the sides are kept, and every edge
// between the sides carries its crossing (-1 elsewhere): 1-3 and 2-2 splits alike.
TEST(CutFromSides, ThePlanesCrossingsGiveTheClippedVolumeForOneThreeAndTwoTwoSplits) {
  std::mt19937 rng(4141);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::normal_distribution<double> normal;
  int splits[2] = {0, 0};  // 1-3, 2-2
  for (int trial = 0; trial < 2000; ++trial) {
    std::array<Eigen::Vector3d, 4> x;
    for (auto& p : x) p = 0.01 * Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng));
    if (std::abs((x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0])) < 1e-8) continue;  // a flat tet
    const Eigen::Vector3d n = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Vector3d through = 0.25 * (x[0] + x[1] + x[2] + x[3]) + 0.002 * Eigen::Vector3d(coordinate(rng), coordinate(rng), coordinate(rng));
    const CutPlane plane{n, n.dot(through)};
    std::array<std::int8_t, 4> side{};
    int above = 0;
    for (size_t j = 0; j < 4; ++j) {
      side[j] = plane.signed_distance(x[j]) > 0.0 ? std::int8_t{1} : std::int8_t{-1};
      above += side[j] > 0 ? 1 : 0;
    }
    if (above == 0 || above == 4) continue;
    ++splits[above == 2 ? 1 : 0];
    std::array<double, 6> ratio{};
    for (size_t k = 0; k < 6; ++k) {
      const double d0 = plane.signed_distance(x[static_cast<size_t>(TET_EDGES[k][0])]);
      const double d1 = plane.signed_distance(x[static_cast<size_t>(TET_EDGES[k][1])]);
      ratio[k] = d0 / (d0 - d1);  // read only where the ends differ
    }
    const TetCut cut = cut_from_sides(x, side, ratio, 0.0, MIN_FRACTION);
    const double tet_m3 = ConvexPiece::tet(x).volume_m3();
    const double above_m3 = ConvexPiece::tet(x).clipped(plane, true, 0.0).volume_m3();
    const double exact = std::clamp(above_m3 / tet_m3, MIN_FRACTION, 1.0 - MIN_FRACTION);
    ASSERT_NEAR(cut.volume_fraction_above, exact, 1e-9) << "trial " << trial;
    EXPECT_EQ(cut.side, side);
    for (size_t k = 0; k < 6; ++k) {
      const bool between = side[static_cast<size_t>(TET_EDGES[k][0])] != side[static_cast<size_t>(TET_EDGES[k][1])];
      EXPECT_EQ(cut.edge_ratio[k], between ? ratio[k] : -1.0) << "edge " << k << ", trial " << trial;
    }
  }
  EXPECT_GT(splits[0], 200);
  EXPECT_GT(splits[1], 200);
}

// A plane through a vertex: its crossings there are held `end_margin` from the ends (distinct cut
// points), while the volume fraction is the clamped fraction of the clip (the geometry is not
// snapped): the sliver below, under the plane, is held at the smallest part.
TEST(CutFromSides, CrossingsAtAVertexAreHeldOffTheEndsAndTheSliverIsClamped) {
  const std::array<Eigen::Vector3d, 4> x = unit_tet();
  // The plane z = 1e-14 (vertex 3 of the unit tet at z = 1 above, the base's three below): the
  // crossings lie at 1e-14 of the edges from the base.
  const std::array<std::int8_t, 4> side{-1, -1, -1, 1};
  std::array<double, 6> ratio{};
  for (size_t k = 0; k < 6; ++k) {
    const double z0 = x[static_cast<size_t>(TET_EDGES[k][0])].z() - 1e-14;
    const double z1 = x[static_cast<size_t>(TET_EDGES[k][1])].z() - 1e-14;
    ratio[k] = z0 / (z0 - z1);
  }
  const double margin = 1e-6;
  const TetCut cut = cut_from_sides(x, side, ratio, margin, MIN_FRACTION);
  for (size_t k = 0; k < 6; ++k) {
    if (cut.edge_ratio[k] < 0.0) continue;
    EXPECT_GE(cut.edge_ratio[k], margin);
    EXPECT_LE(cut.edge_ratio[k], 1.0 - margin);
  }
  EXPECT_NEAR(cut.volume_fraction_above, 1.0 - MIN_FRACTION, 1e-15);  // all but the sliver below z = 1e-14
}

}  // namespace
}  // namespace tissue
