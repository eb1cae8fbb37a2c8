// SurfaceBvh (core/collide/surface_bvh.hpp): segment and sphere queries return exactly what a brute
// force over all triangles returns, on the frog's surface at rest and after a smooth nonlinear
// deformation plus refit; refit keeps the tree's structure and fits its boxes tightly; added
// triangles (cut faces) are found; bad input throws. Hand cases pin down sorting and barycentrics.
#include "core/collide/surface_bvh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <span>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

namespace tissue {
namespace {

const std::filesystem::path MESH_DIR = TISSUE_MESH_DIR;

using Triangles = std::vector<std::array<int, 3>>;

Eigen::Vector3d vertex(const Eigen::VectorXd& positions_m, int v) {
  return positions_m.segment<3>(3 * static_cast<Eigen::Index>(v));
}

Eigen::VectorXd flatten(const std::vector<Eigen::Vector3d>& points) {
  Eigen::VectorXd positions_m(3 * static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) positions_m.segment<3>(3 * static_cast<Eigen::Index>(i)) = points[i];
  return positions_m;
}

struct Frog {
  Triangles triangles;
  Eigen::VectorXd rest_m;
  Eigen::Vector3d lower_m;
  Eigen::Vector3d upper_m;
  double size_m = 0.0;  ///< bounding-box diagonal
};

const Frog& frog() {
  static const Frog loaded = [] {
    const TetMesh mesh = read_mesh(MESH_DIR / "frog.veg");
    Frog f;
    f.triangles = extract_surface(mesh).triangles;
    f.rest_m = flatten(mesh.rest_positions_m);
    const Eigen::Map<const Eigen::Matrix3Xd> points(f.rest_m.data(), 3, f.rest_m.size() / 3);
    f.lower_m = points.rowwise().minCoeff();
    f.upper_m = points.rowwise().maxCoeff();
    f.size_m = (f.upper_m - f.lower_m).norm();
    return f;
  }();
  return loaded;
}

/// A smooth nonlinear deformation of about 15% of the size: sine waves, a twist about z growing
/// with z, and a translation, so that every box moves, grows or shrinks.
Eigen::VectorXd deform(const Frog& f, const Eigen::VectorXd& positions_m) {
  const Eigen::Vector3d centre = 0.5 * (f.lower_m + f.upper_m);
  const double size = f.size_m;
  const double k = 2.0 * std::numbers::pi / size;
  Eigen::VectorXd deformed = positions_m;
  for (Eigen::Index v = 0; v < positions_m.size() / 3; ++v) {
    const Eigen::Vector3d x = positions_m.segment<3>(3 * v) - centre;
    const Eigen::Vector3d wave(std::sin(k * x.y()), std::sin(k * x.z()) * std::cos(k * x.x()), std::sin(k * x.x()));
    const Eigen::Vector3d twisted = Eigen::AngleAxisd(0.8 * x.z() / size, Eigen::Vector3d::UnitZ()) * x;
    deformed.segment<3>(3 * v) = centre + twisted + 0.15 * size * wave + size * Eigen::Vector3d(0.3, -0.2, 0.1);
  }
  return deformed;
}

std::vector<SurfaceBvh::SegmentHit> brute_segment(const Triangles& triangles, const Eigen::Vector3d& a,
                                                  const Eigen::Vector3d& b, const Eigen::VectorXd& positions_m) {
  std::vector<SurfaceBvh::SegmentHit> hits;
  for (size_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    const auto hit = intersect_segment_triangle(a, b, vertex(positions_m, t[0]), vertex(positions_m, t[1]),
                                                vertex(positions_m, t[2]));
    if (hit) hits.push_back({static_cast<int>(i), hit->segment_parameter, hit->barycentric});
  }
  std::sort(hits.begin(), hits.end(), [](const auto& x, const auto& y) {
    return std::pair(x.segment_parameter, x.triangle) < std::pair(y.segment_parameter, y.triangle);
  });
  return hits;
}

std::vector<SurfaceBvh::SphereHit> brute_sphere(const Triangles& triangles, const Eigen::Vector3d& centre,
                                                double radius_m, const Eigen::VectorXd& positions_m) {
  std::vector<SurfaceBvh::SphereHit> hits;
  for (size_t i = 0; i < triangles.size(); ++i) {
    const Eigen::Vector3d x0 = vertex(positions_m, triangles[i][0]);
    const Eigen::Vector3d x1 = vertex(positions_m, triangles[i][1]);
    const Eigen::Vector3d x2 = vertex(positions_m, triangles[i][2]);
    const Eigen::Vector3d w = closest_point_on_triangle(centre, x0, x1, x2);
    const double distance_m = (centre - (w[0] * x0 + w[1] * x1 + w[2] * x2)).norm();
    if (distance_m <= radius_m) hits.push_back({static_cast<int>(i), distance_m, w});
  }
  std::sort(hits.begin(), hits.end(), [](const auto& x, const auto& y) {
    return std::pair(x.distance_m, x.triangle) < std::pair(y.distance_m, y.triangle);
  });
  return hits;
}

/// Same triangles, same order, bit-identical numbers: the BVH runs the same exact tests.
void expect_same(const std::vector<SurfaceBvh::SegmentHit>& bvh, const std::vector<SurfaceBvh::SegmentHit>& brute,
                 int query) {
  ASSERT_EQ(bvh.size(), brute.size()) << "segment " << query;
  for (size_t i = 0; i < bvh.size(); ++i) {
    EXPECT_EQ(bvh[i].triangle, brute[i].triangle) << "segment " << query;
    EXPECT_EQ(bvh[i].segment_parameter, brute[i].segment_parameter) << "segment " << query;
    EXPECT_EQ(bvh[i].barycentric, brute[i].barycentric) << "segment " << query;
  }
}

void expect_same(const std::vector<SurfaceBvh::SphereHit>& bvh, const std::vector<SurfaceBvh::SphereHit>& brute,
                 int query) {
  ASSERT_EQ(bvh.size(), brute.size()) << "sphere " << query;
  for (size_t i = 0; i < bvh.size(); ++i) {
    EXPECT_EQ(bvh[i].triangle, brute[i].triangle) << "sphere " << query;
    EXPECT_EQ(bvh[i].distance_m, brute[i].distance_m) << "sphere " << query;
    EXPECT_EQ(bvh[i].barycentric, brute[i].barycentric) << "sphere " << query;
  }
}

Eigen::Vector3d random_unit(std::mt19937& random) {
  std::normal_distribution<double> normal;
  return Eigen::Vector3d(normal(random), normal(random), normal(random)).normalized();
}

/// A random point of a random triangle.
Eigen::Vector3d random_surface_point(std::mt19937& random, const Triangles& triangles,
                                     const Eigen::VectorXd& positions_m) {
  std::uniform_int_distribution<size_t> pick(0, triangles.size() - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto& t = triangles[pick(random)];
  double u = unit(random);
  double v = unit(random);
  if (u + v > 1.0) std::tie(u, v) = std::pair(1.0 - u, 1.0 - v);
  return (1.0 - u - v) * vertex(positions_m, t[0]) + u * vertex(positions_m, t[1]) + v * vertex(positions_m, t[2]);
}

/// Compares BVH and brute force for 5 x 150 segments: random ones across the bounding box, ones
/// through random surface points, ones starting exactly at a vertex, ones passing through a vertex
/// (up to rounding: the hits lie on corners of the triangles' boxes; without the box margin about
/// 4% of these are pruned wrongly), and axis-aligned ones through a vertex (zero direction components).
/// Returns the number of hits seen.
int compare_segments(const SurfaceBvh& bvh, const Triangles& triangles, const Eigen::VectorXd& positions_m,
                     double size_m, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Index vertex_count = positions_m.size() / 3;
  const Eigen::Map<const Eigen::Matrix3Xd> points(positions_m.data(), 3, vertex_count);
  const Eigen::Vector3d lower = points.rowwise().minCoeff().array() - 0.2 * size_m;
  const Eigen::Vector3d upper = points.rowwise().maxCoeff().array() + 0.2 * size_m;
  const auto in_box = [&] {
    return Eigen::Vector3d(lower.array() +
                           (upper - lower).array() * Eigen::Array3d(unit(random), unit(random), unit(random)));
  };
  std::uniform_int_distribution<int> pick_triangle(0, static_cast<int>(triangles.size()) - 1);
  std::uniform_int_distribution<int> pick_axis(0, 2);
  std::vector<SurfaceBvh::SegmentHit> hits;
  int hit_count = 0;
  for (int query = 0; query < 750; ++query) {
    Eigen::Vector3d a;
    Eigen::Vector3d b;
    if (query < 150) {
      a = in_box();
      b = in_box();
    } else if (query < 300) {
      const Eigen::Vector3d point = random_surface_point(random, triangles, positions_m);
      const Eigen::Vector3d d = (0.01 + 0.5 * unit(random)) * size_m * random_unit(random);
      a = point - unit(random) * d;
      b = a + d;
    } else {
      const int v = triangles[static_cast<size_t>(pick_triangle(random))][static_cast<size_t>(pick_axis(random))];
      const Eigen::Vector3d x = vertex(positions_m, v);
      if (query < 450) {
        a = x;
        b = x + 0.1 * size_m * random_unit(random);
      } else if (query < 600) {
        const Eigen::Vector3d d = 0.1 * size_m * random_unit(random);
        a = x - unit(random) * d;
        b = a + d;
      } else {
        const Eigen::Vector3d axis = Eigen::Vector3d::Unit(pick_axis(random));
        a = x - 0.05 * size_m * axis;
        b = x + 0.05 * size_m * axis;
      }
    }
    bvh.intersect_segment(a, b, positions_m, hits);
    expect_same(hits, brute_segment(triangles, a, b, positions_m), query);
    hit_count += static_cast<int>(hits.size());
  }
  return hit_count;
}

/// Compares BVH and brute force for 300 spheres near the surface (radius up to 10% of the size),
/// 100 far from it, and 100 of radius 0 centred exactly on a vertex. Returns the number of hits seen.
int compare_spheres(const SurfaceBvh& bvh, const Triangles& triangles, const Eigen::VectorXd& positions_m,
                    double size_m, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> pick_triangle(0, static_cast<int>(triangles.size()) - 1);
  std::uniform_int_distribution<int> pick_corner(0, 2);
  std::vector<SurfaceBvh::SphereHit> hits;
  int hit_count = 0;
  for (int query = 0; query < 500; ++query) {
    Eigen::Vector3d centre;
    double radius_m = 0.0;
    if (query < 300) {
      centre = random_surface_point(random, triangles, positions_m) + 0.1 * size_m * unit(random) * random_unit(random);
      radius_m = 0.1 * size_m * unit(random);
    } else if (query < 400) {
      centre = random_surface_point(random, triangles, positions_m) + 2.0 * size_m * random_unit(random);
      radius_m = 0.5 * size_m * unit(random);
    } else {
      centre = vertex(positions_m,
                      triangles[static_cast<size_t>(pick_triangle(random))][static_cast<size_t>(pick_corner(random))]);
    }
    bvh.intersect_sphere(centre, radius_m, positions_m, hits);
    expect_same(hits, brute_sphere(triangles, centre, radius_m, positions_m), query);
    hit_count += static_cast<int>(hits.size());
  }
  return hit_count;
}

/// overlap_box returns candidates: at least every triangle whose exact box meets the query box,
/// at most those whose box grown by the documented margin (1e-9 of the largest coordinate) does.
void compare_boxes(const SurfaceBvh& bvh, const Triangles& triangles, const Eigen::VectorXd& positions_m, double size_m,
                   unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double margin_m = 1e-9 * positions_m.cwiseAbs().maxCoeff();
  std::vector<int> found;
  for (int query = 0; query < 200; ++query) {
    const Eigen::Vector3d corner = random_surface_point(random, triangles, positions_m);
    const Eigen::Vector3d extent = 0.1 * size_m * Eigen::Vector3d(unit(random), unit(random), unit(random));
    const Eigen::Vector3d lower = corner - 0.5 * extent;
    const Eigen::Vector3d upper = corner + 0.5 * extent;
    bvh.overlap_box(lower, upper, found);
    const std::set<int> found_set(found.begin(), found.end());
    ASSERT_EQ(found_set.size(), found.size()) << "box " << query << ": a triangle reported twice";
    for (size_t i = 0; i < triangles.size(); ++i) {
      const Eigen::Vector3d x0 = vertex(positions_m, triangles[i][0]);
      const Eigen::Vector3d x1 = vertex(positions_m, triangles[i][1]);
      const Eigen::Vector3d x2 = vertex(positions_m, triangles[i][2]);
      const Eigen::Vector3d t_lower = x0.cwiseMin(x1).cwiseMin(x2);
      const Eigen::Vector3d t_upper = x0.cwiseMax(x1).cwiseMax(x2);
      const bool exact = (t_lower.array() <= upper.array()).all() && (t_upper.array() >= lower.array()).all();
      const bool grown = (t_lower.array() - 2.0 * margin_m <= upper.array()).all() &&
                         (t_upper.array() + 2.0 * margin_m >= lower.array()).all();
      const bool reported = found_set.count(static_cast<int>(i)) > 0;
      if (exact) {
        EXPECT_TRUE(reported) << "box " << query << " misses triangle " << i;
      }
      if (!grown) {
        EXPECT_FALSE(reported) << "box " << query << " reports far triangle " << i;
      }
    }
  }
}

/// Structure invariants: 2n - 1 nodes, parents listed before their children, each triangle one leaf.
void expect_valid_shape(const std::vector<SurfaceBvh::NodeShape>& shape, int triangle_count) {
  ASSERT_EQ(static_cast<int>(shape.size()), 2 * triangle_count - 1);
  std::vector<int> leaf_count(static_cast<size_t>(triangle_count), 0);
  std::vector<int> child_count(shape.size(), 0);
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i == 0) {
      EXPECT_EQ(shape[i].parent, -1);
    } else {
      ASSERT_GE(shape[i].parent, 0);
      ASSERT_LT(shape[i].parent, static_cast<int>(i));
      ++child_count[static_cast<size_t>(shape[i].parent)];
    }
    if (shape[i].triangle >= 0) ++leaf_count[static_cast<size_t>(shape[i].triangle)];
  }
  for (const int count : leaf_count) EXPECT_EQ(count, 1);
  for (size_t i = 0; i < shape.size(); ++i) EXPECT_EQ(child_count[i], shape[i].triangle >= 0 ? 0 : 2) << i;
}

TEST(SurfaceBvh, FrogQueriesEqualBruteForceAtRest) {
  const Frog& f = frog();
  ASSERT_GT(f.triangles.size(), 1000u);
  const SurfaceBvh bvh(f.triangles, f.rest_m);
  EXPECT_EQ(bvh.triangle_count(), static_cast<int>(f.triangles.size()));
  expect_valid_shape(bvh.shape(), bvh.triangle_count());
  EXPECT_GT(compare_segments(bvh, f.triangles, f.rest_m, f.size_m, 11), 600);
  EXPECT_GT(compare_spheres(bvh, f.triangles, f.rest_m, f.size_m, 12), 1000);
  compare_boxes(bvh, f.triangles, f.rest_m, f.size_m, 13);
}

TEST(SurfaceBvh, FrogQueriesEqualBruteForceAfterDeformationAndRefit) {
  const Frog& f = frog();
  SurfaceBvh bvh(f.triangles, f.rest_m);
  const std::vector<SurfaceBvh::NodeShape> before = bvh.shape();
  const Eigen::VectorXd deformed = deform(f, f.rest_m);
  bvh.refit(deformed);
  EXPECT_EQ(bvh.shape(), before);  // refitted, not rebuilt
  EXPECT_GT(compare_segments(bvh, f.triangles, deformed, f.size_m, 21), 600);
  EXPECT_GT(compare_spheres(bvh, f.triangles, deformed, f.size_m, 22), 1000);
  compare_boxes(bvh, f.triangles, deformed, f.size_m, 23);
  // And back: boxes shrink again to the rest configuration.
  bvh.refit(f.rest_m);
  EXPECT_EQ(bvh.shape(), before);
  compare_boxes(bvh, f.triangles, f.rest_m, f.size_m, 24);
  EXPECT_GT(compare_segments(bvh, f.triangles, f.rest_m, f.size_m, 25), 600);
}

TEST(SurfaceBvh, QueryResultsDoNotDependOnTheTreesInsertionHistory) {
  // The same triangles, one tree built at rest, one grown by insertion at a deformed state (as a
  // restored state rebuilds it): different trees, the same answers in the same order.
  const Frog& f = frog();
  const Eigen::VectorXd deformed = deform(f, f.rest_m);
  SurfaceBvh built(f.triangles, f.rest_m);
  built.refit(deformed);
  const size_t half = f.triangles.size() / 2;
  SurfaceBvh grown(Triangles(f.triangles.begin(), f.triangles.begin() + static_cast<long>(half)), f.rest_m);
  grown.refit(deformed);
  grown.add_triangles(std::span(f.triangles).subspan(half), deformed);
  ASSERT_NE(built.shape(), grown.shape());
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<int> from_built, from_grown;
  for (int query = 0; query < 200; ++query) {
    Eigen::Vector3d a, b;
    for (int axis = 0; axis < 3; ++axis) {
      a(axis) = f.lower_m(axis) - 0.1 * f.size_m + 1.2 * f.size_m * unit(rng);
      b(axis) = a(axis) + 0.2 * f.size_m * unit(rng);
    }
    built.overlap_box(a, b, from_built);
    grown.overlap_box(a, b, from_grown);
    EXPECT_EQ(from_built, from_grown);
    EXPECT_TRUE(std::is_sorted(from_built.begin(), from_built.end()));
  }
}

TEST(SurfaceBvh, SphereOfRadiusZeroOnAVertexFindsExactlyItsTriangles) {
  const Frog& f = frog();
  const SurfaceBvh bvh(f.triangles, f.rest_m);
  std::vector<SurfaceBvh::SphereHit> hits;
  const size_t n = f.triangles.size();
  for (const int v : {f.triangles[0][0], f.triangles[n / 3][1], f.triangles[n / 2][2], f.triangles[n - 1][0]}) {
    std::set<int> around;
    for (size_t i = 0; i < f.triangles.size(); ++i) {
      if (std::find(f.triangles[i].begin(), f.triangles[i].end(), v) != f.triangles[i].end()) {
        around.insert(static_cast<int>(i));
      }
    }
    ASSERT_GE(around.size(), 3u);  // a closed surface has at least three triangles at each vertex
    bvh.intersect_sphere(vertex(f.rest_m, v), 0.0, f.rest_m, hits);
    std::set<int> found;
    for (const auto& hit : hits) {
      found.insert(hit.triangle);
      EXPECT_EQ(hit.distance_m, 0.0);
      const auto& t = f.triangles[static_cast<size_t>(hit.triangle)];
      const auto corner = std::find(t.begin(), t.end(), v) - t.begin();
      EXPECT_EQ(hit.barycentric[corner], 1.0);
    }
    EXPECT_EQ(found, around) << "vertex " << v;
  }
}

// Unit square in z = 0 as two triangles sharing the diagonal 0-2.
const Triangles square_triangles = {{0, 1, 2}, {0, 2, 3}};
Eigen::VectorXd square_positions() { return flatten({{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}); }

TEST(SurfaceBvh, SegmentThroughASharedEdgeHitsBothTrianglesSorted) {
  const Eigen::VectorXd x = square_positions();
  const SurfaceBvh bvh(square_triangles, x);
  std::vector<SurfaceBvh::SegmentHit> hits;
  bvh.intersect_segment({0.5, 0.5, 1.0}, {0.5, 0.5, -1.0}, x, hits);
  ASSERT_EQ(hits.size(), 2u);
  EXPECT_EQ(hits[0].triangle, 0);
  EXPECT_EQ(hits[1].triangle, 1);
  EXPECT_EQ(hits[0].segment_parameter, 0.5);
  EXPECT_EQ(hits[1].segment_parameter, 0.5);
  EXPECT_EQ(hits[0].barycentric, Eigen::Vector3d(0.5, 0.0, 0.5));
  EXPECT_EQ(hits[1].barycentric, Eigen::Vector3d(0.5, 0.5, 0.0));
  // Starting below: one crossing, at s = 1/4; starting above the square: none.
  bvh.intersect_segment({0.75, 0.25, -1.0}, {0.75, 0.25, 3.0}, x, hits);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].triangle, 0);
  EXPECT_EQ(hits[0].segment_parameter, 0.25);
  bvh.intersect_segment({0.75, 0.25, 0.5}, {0.75, 0.25, 3.0}, x, hits);
  EXPECT_TRUE(hits.empty());
}

TEST(SurfaceBvh, SphereHitsAreSortedByDistanceWithTheClosestPoint) {
  const Eigen::VectorXd x = square_positions();
  const SurfaceBvh bvh(square_triangles, x);
  std::vector<SurfaceBvh::SphereHit> hits;
  // (2, 0.5, 0) is 1 from triangle 0 (closest point (1, 0.5, 0), on its edge 1-2) and sqrt(1.25)
  // from triangle 1 (closest point its vertex (1, 1, 0)).
  bvh.intersect_sphere({2.0, 0.5, 0.0}, 1.0, x, hits);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].triangle, 0);
  EXPECT_EQ(hits[0].distance_m, 1.0);
  EXPECT_EQ(hits[0].barycentric, Eigen::Vector3d(0.0, 0.5, 0.5));
  bvh.intersect_sphere({2.0, 0.5, 0.0}, 1.2, x, hits);
  ASSERT_EQ(hits.size(), 2u);
  EXPECT_EQ(hits[0].triangle, 0);
  EXPECT_EQ(hits[1].triangle, 1);
  EXPECT_DOUBLE_EQ(hits[1].distance_m, std::sqrt(1.25));
  EXPECT_EQ(hits[1].barycentric, Eigen::Vector3d(0.0, 1.0, 0.0));
  bvh.intersect_sphere({2.0, 0.5, 0.0}, 1.1, x, hits);
  ASSERT_EQ(hits.size(), 1u);
  bvh.intersect_sphere({2.0, 0.5, 0.0}, 0.999, x, hits);
  EXPECT_TRUE(hits.empty());
}

TEST(SurfaceBvh, AddedTrianglesAreFoundAndRefitted) {
  const Frog& f = frog();
  SurfaceBvh bvh(f.triangles, f.rest_m);
  const int n = bvh.triangle_count();
  // A cut face on three new vertices inside the bounding box, appended to the positions.
  const Eigen::Index old_size = f.rest_m.size();
  Eigen::VectorXd x(old_size + 9);
  x << f.rest_m, Eigen::VectorXd::Zero(9);
  const Eigen::Vector3d centre = 0.5 * (f.lower_m + f.upper_m);
  const double r = 0.1 * f.size_m;
  x.segment<3>(old_size) = centre + Eigen::Vector3d(-r, -r, 0.0);
  x.segment<3>(old_size + 3) = centre + Eigen::Vector3d(r, -r, 0.0);
  x.segment<3>(old_size + 6) = centre + Eigen::Vector3d(0.0, r, 0.0);
  const int first_new_vertex = static_cast<int>(old_size / 3);
  Triangles triangles = f.triangles;
  triangles.push_back({first_new_vertex, first_new_vertex + 1, first_new_vertex + 2});
  EXPECT_EQ(bvh.add_triangle(triangles.back(), x), n);
  // And one on existing vertices: a triangle spanning the body.
  triangles.push_back({f.triangles[0][0], f.triangles[n / 2][1], f.triangles[n - 1][2]});
  EXPECT_EQ(bvh.add_triangle(triangles.back(), x), n + 1);
  EXPECT_EQ(bvh.triangle_count(), n + 2);
  EXPECT_EQ(bvh.triangles(), triangles);
  expect_valid_shape(bvh.shape(), n + 2);

  std::vector<SurfaceBvh::SegmentHit> hits;
  bvh.intersect_segment(centre + Eigen::Vector3d(0.0, 0.0, r), centre - Eigen::Vector3d(0.0, 0.0, r), x, hits);
  const auto new_hit = std::find_if(hits.begin(), hits.end(), [&](const auto& h) { return h.triangle == n; });
  ASSERT_NE(new_hit, hits.end());
  EXPECT_NEAR(new_hit->segment_parameter, 0.5, 1e-14);
  EXPECT_TRUE(new_hit->barycentric.isApprox(Eigen::Vector3d(0.25, 0.25, 0.5), 1e-12));
  EXPECT_GT(compare_segments(bvh, triangles, x, f.size_m, 31), 600);
  EXPECT_GT(compare_spheres(bvh, triangles, x, f.size_m, 32), 1000);

  const std::vector<SurfaceBvh::NodeShape> before = bvh.shape();
  const Eigen::VectorXd deformed = deform(f, x);
  bvh.refit(deformed);
  EXPECT_EQ(bvh.shape(), before);
  EXPECT_GT(compare_segments(bvh, triangles, deformed, f.size_m, 33), 600);
  EXPECT_GT(compare_spheres(bvh, triangles, deformed, f.size_m, 34), 1000);
  compare_boxes(bvh, triangles, deformed, f.size_m, 35);
}

// Faces taken out (the faces of retired cut tets, issue 41) are never returned, are not refitted,
// keep their ids, and the rest answer as brute force over the kept triangles does.
TEST(SurfaceBvh, RemovedTrianglesAreNeverFoundAndTheRestAnswerAsBefore) {
  const Frog& f = frog();
  SurfaceBvh bvh(f.triangles, f.rest_m);
  const int n = bvh.triangle_count();
  std::vector<int> removed;
  for (int id = 0; id < n; id += 3) removed.push_back(id);
  bvh.remove_triangles(removed);
  bvh.remove_triangles(std::vector<int>{0, 3});  // out already: skipped
  Triangles kept;
  std::vector<int> kept_id;
  for (int id = 0; id < n; ++id) {
    EXPECT_EQ(bvh.in_tree(id), id % 3 != 0) << id;
    EXPECT_EQ(bvh.triangle(id), f.triangles[static_cast<size_t>(id)]);  // ids and corners stay
    if (id % 3 == 0) continue;
    kept.push_back(f.triangles[static_cast<size_t>(id)]);
    kept_id.push_back(id);
  }
  // The leaves of the kept triangles only, each once.
  int leaves = 0;
  for (const SurfaceBvh::NodeShape& node : bvh.shape()) {
    if (node.triangle < 0) continue;
    ++leaves;
    EXPECT_NE(node.triangle % 3, 0);
  }
  EXPECT_EQ(leaves, static_cast<int>(kept.size()));

  const Eigen::VectorXd deformed = deform(f, f.rest_m);
  bvh.refit(deformed);
  std::mt19937 random(41);
  std::vector<SurfaceBvh::SegmentHit> segment_hits;
  std::vector<SurfaceBvh::SphereHit> sphere_hits;
  int hits_seen = 0;
  for (int query = 0; query < 400; ++query) {
    const Eigen::Vector3d point = random_surface_point(random, f.triangles, deformed);
    const Eigen::Vector3d d = 0.3 * f.size_m * random_unit(random);
    bvh.intersect_segment(point - d, point + d, deformed, segment_hits);
    std::vector<SurfaceBvh::SegmentHit> brute = brute_segment(kept, point - d, point + d, deformed);
    for (SurfaceBvh::SegmentHit& hit : brute) hit.triangle = kept_id[static_cast<size_t>(hit.triangle)];
    expect_same(segment_hits, brute, query);
    bvh.intersect_sphere(point, 0.05 * f.size_m, deformed, sphere_hits);
    std::vector<SurfaceBvh::SphereHit> brute_hits = brute_sphere(kept, point, 0.05 * f.size_m, deformed);
    for (SurfaceBvh::SphereHit& hit : brute_hits) hit.triangle = kept_id[static_cast<size_t>(hit.triangle)];
    expect_same(sphere_hits, brute_hits, query);
    hits_seen += static_cast<int>(segment_hits.size() + sphere_hits.size());
  }
  EXPECT_GT(hits_seen, 1000);
  EXPECT_THROW(bvh.remove_triangles(std::vector<int>{n}), std::invalid_argument);
  EXPECT_THROW(bvh.remove_triangles(std::vector<int>{-1}), std::invalid_argument);
}

TEST(SurfaceBvh, EmptyTreeGrowsByAddition) {
  const Eigen::VectorXd x = square_positions();
  SurfaceBvh bvh({}, x);
  EXPECT_EQ(bvh.triangle_count(), 0);
  EXPECT_TRUE(bvh.shape().empty());
  std::vector<SurfaceBvh::SegmentHit> hits{{7, 0.5, Eigen::Vector3d::Zero()}};  // cleared by the query
  bvh.intersect_segment({0.5, 0.5, 1.0}, {0.5, 0.5, -1.0}, x, hits);
  EXPECT_TRUE(hits.empty());
  bvh.refit(x);
  EXPECT_EQ(bvh.add_triangle(square_triangles[1], x), 0);
  expect_valid_shape(bvh.shape(), 1);
  bvh.intersect_segment({0.25, 0.5, 1.0}, {0.25, 0.5, -1.0}, x, hits);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].triangle, 0);
  EXPECT_EQ(bvh.add_triangle(square_triangles[0], x), 1);
  expect_valid_shape(bvh.shape(), 2);
  bvh.intersect_segment({0.75, 0.25, 1.0}, {0.75, 0.25, -1.0}, x, hits);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].triangle, 1);
}

TEST(SurfaceBvh, MovedTreeKeepsWorking) {
  const Eigen::VectorXd x = square_positions();
  SurfaceBvh moved_from(square_triangles, x);
  SurfaceBvh bvh(std::move(moved_from));
  std::vector<SurfaceBvh::SegmentHit> hits;
  bvh.intersect_segment({0.75, 0.25, 1.0}, {0.75, 0.25, -1.0}, x, hits);
  ASSERT_EQ(hits.size(), 1u);
  SurfaceBvh other({}, x);
  other = std::move(bvh);
  other.intersect_segment({0.75, 0.25, 1.0}, {0.75, 0.25, -1.0}, x, hits);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(other.triangle_count(), 2);
}

TEST(SurfaceBvh, BadInputThrows) {
  const Eigen::VectorXd x = square_positions();  // 4 vertices
  EXPECT_THROW(SurfaceBvh({{0, 1, 4}}, x), std::invalid_argument);
  EXPECT_THROW(SurfaceBvh({{0, -1, 2}}, x), std::invalid_argument);
  EXPECT_THROW(SurfaceBvh({{0, 1, 2}}, x.head(8)), std::invalid_argument);  // vertex 2 incomplete
  SurfaceBvh bvh(square_triangles, x);
  EXPECT_THROW(bvh.add_triangle({1, 2, 4}, x), std::invalid_argument);
  EXPECT_THROW(bvh.add_triangle({-3, 2, 1}, x), std::invalid_argument);
  EXPECT_EQ(bvh.triangle_count(), 2);  // nothing was added
  expect_valid_shape(bvh.shape(), 2);
  EXPECT_THROW(bvh.refit(x.head(9)), std::invalid_argument);  // vertex 3 missing
  std::vector<SurfaceBvh::SegmentHit> segment_hits;
  EXPECT_THROW(bvh.intersect_segment({0, 0, 1}, {0, 0, -1}, x.head(9), segment_hits), std::invalid_argument);
  std::vector<SurfaceBvh::SphereHit> sphere_hits;
  EXPECT_THROW(bvh.intersect_sphere({0, 0, 0}, 1.0, x.head(9), sphere_hits), std::invalid_argument);
  EXPECT_THROW(bvh.intersect_sphere({0, 0, 0}, -1.0, x, sphere_hits), std::invalid_argument);
  EXPECT_THROW(bvh.intersect_sphere({0, 0, 0}, std::nan(""), x, sphere_hits), std::invalid_argument);
  // Still answers correctly afterwards.
  bvh.intersect_segment({0.75, 0.25, 1.0}, {0.75, 0.25, -1.0}, x, segment_hits);
  ASSERT_EQ(segment_hits.size(), 1u);
  EXPECT_EQ(segment_hits[0].triangle, 0);
}

}  // namespace
}  // namespace tissue
