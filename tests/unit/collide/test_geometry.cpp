// Geometric predicates (core/collide/geometry.hpp): segment/triangle crossings and closest points
// on hand-computed cases (every Voronoi region, edges, vertices, end points, parallel, coplanar,
// degenerate), then random cases checked against what geometry predicts (the hit point lies on
// both the segment and the triangle; the closest point satisfies the projection inequality).
#include "core/collide/geometry.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>

namespace tissue {
namespace {

// The unit right triangle in z = 0 used by the hand cases.
const Eigen::Vector3d unit_t0(0.0, 0.0, 0.0);
const Eigen::Vector3d unit_t1(1.0, 0.0, 0.0);
const Eigen::Vector3d unit_t2(0.0, 1.0, 0.0);

std::optional<SegmentTriangleHit> cross_unit(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return intersect_segment_triangle(a, b, unit_t0, unit_t1, unit_t2);
}

// Every value in these hand cases is a dyadic rational: the arithmetic is exact, so equality is asserted.
TEST(IntersectSegmentTriangle, HitInTheMiddleGivesParameterAndBarycentric) {
  const auto hit = cross_unit({0.25, 0.25, 1.0}, {0.25, 0.25, -1.0});
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->segment_parameter, 0.5);
  EXPECT_EQ(hit->barycentric, Eigen::Vector3d(0.5, 0.25, 0.25));
}

TEST(IntersectSegmentTriangle, BothSidesAndBothWindingsHit) {
  // From below, and with the triangle wound the other way: same point, barycentric permuted.
  const auto from_below = cross_unit({0.25, 0.5, -0.5}, {0.25, 0.5, 1.5});
  ASSERT_TRUE(from_below);
  EXPECT_EQ(from_below->segment_parameter, 0.25);
  EXPECT_EQ(from_below->barycentric, Eigen::Vector3d(0.25, 0.25, 0.5));
  const auto reversed = intersect_segment_triangle({0.25, 0.5, -0.5}, {0.25, 0.5, 1.5}, unit_t0, unit_t2, unit_t1);
  ASSERT_TRUE(reversed);
  EXPECT_EQ(reversed->segment_parameter, 0.25);
  EXPECT_EQ(reversed->barycentric, Eigen::Vector3d(0.25, 0.5, 0.25));
}

TEST(IntersectSegmentTriangle, EdgesAndVerticesBelongToTheClosedTriangle) {
  const auto on_edge01 = cross_unit({0.5, 0.0, 1.0}, {0.5, 0.0, -1.0});
  ASSERT_TRUE(on_edge01);
  EXPECT_EQ(on_edge01->barycentric, Eigen::Vector3d(0.5, 0.5, 0.0));
  const auto on_hypotenuse = cross_unit({0.5, 0.5, 1.0}, {0.5, 0.5, -1.0});
  ASSERT_TRUE(on_hypotenuse);
  EXPECT_EQ(on_hypotenuse->barycentric, Eigen::Vector3d(0.0, 0.5, 0.5));
  const auto on_vertex = cross_unit({0.0, 1.0, 1.0}, {0.0, 1.0, -1.0});
  ASSERT_TRUE(on_vertex);
  EXPECT_EQ(on_vertex->barycentric, Eigen::Vector3d(0.0, 0.0, 1.0));
}

TEST(IntersectSegmentTriangle, JustOutsideAnEdgeMisses) {
  EXPECT_FALSE(cross_unit({0.5, -1e-9, 1.0}, {0.5, -1e-9, -1.0}));
  EXPECT_FALSE(cross_unit({0.5 + 1e-9, 0.5, 1.0}, {0.5 + 1e-9, 0.5, -1.0}));
  EXPECT_FALSE(cross_unit({-1e-9, 0.5, 1.0}, {-1e-9, 0.5, -1.0}));
  EXPECT_FALSE(cross_unit({2.0, 2.0, 1.0}, {2.0, 2.0, -1.0}));
}

TEST(IntersectSegmentTriangle, EndPointsAreIncludedAndShortSegmentsMiss) {
  const auto ends_on = cross_unit({0.25, 0.25, 1.0}, {0.25, 0.25, 0.0});
  ASSERT_TRUE(ends_on);
  EXPECT_EQ(ends_on->segment_parameter, 1.0);
  const auto starts_on = cross_unit({0.25, 0.25, 0.0}, {0.25, 0.25, 1.0});
  ASSERT_TRUE(starts_on);
  EXPECT_EQ(starts_on->segment_parameter, 0.0);
  EXPECT_FALSE(cross_unit({0.25, 0.25, 1.0}, {0.25, 0.25, 1e-9}));
  EXPECT_FALSE(cross_unit({0.25, 0.25, -1e-9}, {0.25, 0.25, -1.0}));
}

TEST(IntersectSegmentTriangle, ParallelAndCoplanarSegmentsDoNotCross) {
  EXPECT_FALSE(cross_unit({-1.0, 0.25, 0.5}, {2.0, 0.25, 0.5}));  // parallel, above
  EXPECT_FALSE(cross_unit({-1.0, 0.25, 0.0}, {2.0, 0.25, 0.0}));  // in the plane, through the triangle
}

TEST(IntersectSegmentTriangle, DegenerateTrianglesNeverHit) {
  const Eigen::Vector3d a(0.5, 0.5, 1.0);
  const Eigen::Vector3d b(0.5, -0.5, -1.0);  // crosses the x axis at (0.5, 0, 0)
  EXPECT_FALSE(intersect_segment_triangle(a, b, unit_t0, unit_t1, {2.0, 0.0, 0.0}));  // collinear
  EXPECT_FALSE(intersect_segment_triangle(a, b, unit_t1, unit_t1, unit_t1));          // a point
  // Area^2 at 1e-34 of |edge|^4: below the documented 1e-30 threshold.
  EXPECT_FALSE(intersect_segment_triangle(a, b, unit_t0, unit_t1, {0.5, 1e-17, 0.0}));
}

TEST(IntersectSegmentTriangle, RandomHitsLieOnBothTheSegmentAndTheTriangle) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int hits = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d x0(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d x1(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d x2(coordinate(random), coordinate(random), coordinate(random));
    // A point with barycentric (w0, w1, w2) in [-0.2, 1.2]: inside the triangle iff all are >= 0.
    const double w1 = 1.4 * unit(random) - 0.2;
    const double w2 = 1.4 * unit(random) - 0.2;
    const Eigen::Vector3d w(1.0 - w1 - w2, w1, w2);
    const Eigen::Vector3d point = w[0] * x0 + w[1] * x1 + w[2] * x2;
    const Eigen::Vector3d direction(coordinate(random), coordinate(random), coordinate(random));
    const double s = 1.4 * unit(random) - 0.2;
    const Eigen::Vector3d a = point - s * direction;
    const Eigen::Vector3d b = a + direction;
    const auto hit = intersect_segment_triangle(a, b, x0, x1, x2);
    // Well-conditioned cases only: the segment at least 1e-3 (sine) off the plane, the triangle's
    // area at least 1e-3 of its longest edge squared. Errors are then below 1e-16 * 1e6 = 1e-10.
    const Eigen::Vector3d normal = (x1 - x0).cross(x2 - x0);
    const double longest_edge_squared =
        std::max({(x1 - x0).squaredNorm(), (x2 - x0).squaredNorm(), (x2 - x1).squaredNorm()});
    const double sine = std::abs(direction.normalized().dot(normal.normalized()));
    if (sine < 1e-3 || normal.norm() < 1e-3 * longest_edge_squared) continue;
    // Away from the boundaries (1e-6), the answer is decided: hit iff w >= 0 and s in [0, 1].
    if (w.minCoeff() < -1e-6 || s < -1e-6 || s > 1.0 + 1e-6) {
      EXPECT_FALSE(hit) << "trial " << trial;
      continue;
    }
    if (w.minCoeff() < 1e-6 || s < 1e-6 || s > 1.0 - 1e-6) continue;
    ASSERT_TRUE(hit) << "trial " << trial;
    ++hits;
    EXPECT_NEAR(hit->segment_parameter, s, 1e-9);
    EXPECT_LT((hit->barycentric - w).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_NEAR(hit->barycentric.sum(), 1.0, 1e-14);
  }
  EXPECT_GT(hits, 200);  // the comparison really ran
}

TEST(ClosestPointOnTriangle, EveryVoronoiRegionOfTheUnitTriangle) {
  // Face region (any height above), the three vertex regions, the three edge regions.
  EXPECT_TRUE(closest_point_on_triangle({0.25, 0.5, 5.0}, unit_t0, unit_t1, unit_t2)
                  .isApprox(Eigen::Vector3d(0.25, 0.25, 0.5)));
  EXPECT_EQ(closest_point_on_triangle({-1.0, -1.0, 2.0}, unit_t0, unit_t1, unit_t2), Eigen::Vector3d(1.0, 0.0, 0.0));
  EXPECT_EQ(closest_point_on_triangle({2.0, -0.5, 0.0}, unit_t0, unit_t1, unit_t2), Eigen::Vector3d(0.0, 1.0, 0.0));
  EXPECT_EQ(closest_point_on_triangle({-0.5, 2.0, 1.0}, unit_t0, unit_t1, unit_t2), Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_EQ(closest_point_on_triangle({0.25, -2.0, 1.0}, unit_t0, unit_t1, unit_t2), Eigen::Vector3d(0.75, 0.25, 0.0));
  EXPECT_EQ(closest_point_on_triangle({-2.0, 0.375, -1.0}, unit_t0, unit_t1, unit_t2),
            Eigen::Vector3d(0.625, 0.0, 0.375));
  EXPECT_EQ(closest_point_on_triangle({1.0, 1.0, 0.5}, unit_t0, unit_t1, unit_t2), Eigen::Vector3d(0.0, 0.5, 0.5));
  // A point of the triangle is its own closest point.
  EXPECT_EQ(closest_point_on_triangle({0.25, 0.25, 0.0}, unit_t0, unit_t1, unit_t2), Eigen::Vector3d(0.5, 0.25, 0.25));
}

TEST(ClosestPointOnTriangle, DegenerateTrianglesGiveTheClosestPointOfTheirSegment) {
  // Collinear: the closest point of (1.5, 1, 0) on the segment [0, 2] x {0} is (1.5, 0, 0).
  const Eigen::Vector3d collinear = closest_point_on_triangle({1.5, 1.0, 0.0}, unit_t0, unit_t1, {2.0, 0.0, 0.0});
  EXPECT_TRUE((collinear.x() * unit_t0 + collinear.y() * unit_t1 + collinear.z() * Eigen::Vector3d(2.0, 0.0, 0.0))
                  .isApprox(Eigen::Vector3d(1.5, 0.0, 0.0)));
  EXPECT_GE(collinear.minCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(collinear.sum(), 1.0);
  const Eigen::Vector3d point = closest_point_on_triangle({3.0, 1.0, 0.0}, unit_t1, unit_t1, unit_t1);
  EXPECT_GE(point.minCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(point.sum(), 1.0);
}

TEST(ClosestPointOnTriangle, RandomCasesSatisfyTheProjectionInequality) {
  // q is the closest point of a convex set to p iff (p - q) . (y - q) <= 0 for every y of the set;
  // by linearity it suffices for the three vertices. Rounding: |p - q| |y - q| ~ 10, so 1e-13.
  std::mt19937 random(5);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int trial = 0; trial < 5000; ++trial) {
    const Eigen::Vector3d x0(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d x1(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d x2(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d p = 2.0 * Eigen::Vector3d(coordinate(random), coordinate(random), coordinate(random));
    const Eigen::Vector3d w = closest_point_on_triangle(p, x0, x1, x2);
    ASSERT_GE(w.minCoeff(), 0.0) << "trial " << trial;
    ASSERT_NEAR(w.sum(), 1.0, 1e-15) << "trial " << trial;
    const Eigen::Vector3d q = w[0] * x0 + w[1] * x1 + w[2] * x2;
    for (const Eigen::Vector3d* y : {&x0, &x1, &x2}) {
      EXPECT_LE((p - q).dot(*y - q), 1e-13) << "trial " << trial;
    }
  }
}

TEST(ClosestPointOnTriangle, AgreesWithTheSegmentHitOnTheTriangle) {
  // A crossing point is on the triangle: its closest point is itself.
  const auto hit =
      intersect_segment_triangle({0.3, 0.1, 2.0}, {-0.1, 0.5, -3.0}, {-1, -1, 0.5}, {2, 0, -0.5}, {0, 2, 0.25});
  ASSERT_TRUE(hit);
  const Eigen::Vector3d x0(-1, -1, 0.5);
  const Eigen::Vector3d x1(2, 0, -0.5);
  const Eigen::Vector3d x2(0, 2, 0.25);
  const Eigen::Vector3d point = hit->barycentric[0] * x0 + hit->barycentric[1] * x1 + hit->barycentric[2] * x2;
  EXPECT_LT((closest_point_on_triangle(point, x0, x1, x2) - hit->barycentric).norm(), 1e-12);
  const Eigen::Vector3d on_segment =
      Eigen::Vector3d(0.3, 0.1, 2.0) + hit->segment_parameter * Eigen::Vector3d(-0.4, 0.4, -5.0);
  EXPECT_LT((on_segment - point).norm(), 1e-14);
}

TEST(TetBarycentric, UnitTetAndDegenerateTet) {
  const Eigen::Vector3d x3(0.0, 0.0, 1.0);
  const auto inside = tet_barycentric({0.125, 0.25, 0.5}, unit_t0, unit_t1, unit_t2, x3);
  ASSERT_TRUE(inside);
  EXPECT_TRUE(inside->isApprox(Eigen::Vector4d(0.125, 0.125, 0.25, 0.5), 1e-14));
  const auto outside = tet_barycentric({1.0, 1.0, 1.0}, unit_t0, unit_t1, unit_t2, x3);
  ASSERT_TRUE(outside);
  EXPECT_TRUE(outside->isApprox(Eigen::Vector4d(-2.0, 1.0, 1.0, 1.0), 1e-14));
  EXPECT_FALSE(tet_barycentric({0.1, 0.1, 0.0}, unit_t0, unit_t1, unit_t2, {1.0, 1.0, 0.0}));  // flat
}

TEST(TetBarycentric, RandomPointsAreReconstructed) {
  std::mt19937 random(9);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    Eigen::Vector3d x[4];
    for (Eigen::Vector3d& v : x) v = {coordinate(random), coordinate(random), coordinate(random)};
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    const auto w = tet_barycentric(p, x[0], x[1], x[2], x[3]);
    ASSERT_TRUE(w);
    // Error ~ 1e-16 times the condition number of the edge matrix. Keep the tets whose edges differ
    // by at most 10x and whose |det| is at least 0.05 of the edge-length product: condition < 1e5.
    Eigen::Matrix3d edges;
    edges << x[1] - x[0], x[2] - x[0], x[3] - x[0];
    const Eigen::Vector3d lengths = edges.colwise().norm();
    if (lengths.minCoeff() < 0.1 * lengths.maxCoeff()) continue;
    if (std::abs(edges.determinant()) < 0.05 * lengths.prod()) continue;
    ++checked;
    EXPECT_NEAR(w->sum(), 1.0, 1e-12);
    EXPECT_LT(((*w)[0] * x[0] + (*w)[1] * x[1] + (*w)[2] * x[2] + (*w)[3] * x[3] - p).norm(), 1e-12);
  }
  EXPECT_GT(checked, 50);
}

}  // namespace
}  // namespace tissue
