// Tests of the god-object point contact: when a contact starts and ends (and refusing a NaN tool
// tip without a trace), the near side holding a tool pushed through a thin slab, the slide landing
// on the closest surface point, and the proxy staying a material point of the surface, on the
// surface and closest to the HIP while the frog swings under gravity.
#include "core/contact/point_contact.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/box_mesh.hpp"

#include "contact/frog_scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>

namespace tissue {
namespace {

using namespace contact_test;

// The closest point of the whole surface to q, by brute force over every triangle.
struct BruteForce {
  double distance_m = std::numeric_limits<double>::infinity();
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // of the triangle it lies on
};
BruteForce closest_by_brute_force(const Eigen::Vector3d& q, const SurfaceTriangles& triangles,
                                  const Eigen::VectorXd& x) {
  BruteForce best;
  for (const auto& t : triangles) {
    const Eigen::Vector3d b =
        closest_point_on_triangle(q, x.segment<3>(3 * t[0]), x.segment<3>(3 * t[1]), x.segment<3>(3 * t[2]));
    const Eigen::Vector3d p =
        b[0] * x.segment<3>(3 * t[0]) + b[1] * x.segment<3>(3 * t[1]) + b[2] * x.segment<3>(3 * t[2]);
    if ((q - p).norm() < best.distance_m) best = BruteForce{(q - p).norm(), p, unit_normal(t, x)};
  }
  return best;
}

// How far the god-object's proxy may be from the HIP beyond the closest surface distance. The
// slide stops at a local minimum of the distance (the god-object holds the face it presses, it
// does not jump to another face that became nearer); on a faceted surface the gap between a local
// minimum on face A at distance d and a nearer one on face B, their normals at angle theta, is at
// most 2 d sin^2(theta / 2) / cos(theta / 2) (in the wedge of the two planes, feet on the faces).
double faceting_tolerance_m(double proxy_distance_m, const Eigen::Vector3d& proxy_normal,
                            const Eigen::Vector3d& closest_normal) {
  const double theta = std::acos(std::clamp(proxy_normal.dot(closest_normal), -1.0, 1.0));
  return 2.0 * proxy_distance_m * std::pow(std::sin(theta / 2), 2) / std::cos(theta / 2) + 1e-15;
}

// Inside the body: in some tet (brute force).
bool inside_by_tets(const Eigen::Vector3d& q, const TetMesh& mesh) {
  for (const Tet& t : mesh.tets) {
    const auto b = tet_barycentric(
        q, mesh.rest_positions_m[static_cast<size_t>(t[0])], mesh.rest_positions_m[static_cast<size_t>(t[1])],
        mesh.rest_positions_m[static_cast<size_t>(t[2])], mesh.rest_positions_m[static_cast<size_t>(t[3])]);
    if (b && b->minCoeff() >= 0.0) return true;
  }
  return false;
}

struct FrogSurface {
  TetMesh mesh = frog_mesh();
  SurfaceMesh surface = extract_surface(mesh);
  Eigen::VectorXd rest = rest_positions(mesh);
  SurfaceBvh bvh{surface.triangles, rest};
  VertexTriangles adjacency = [this] {
    VertexTriangles built;
    built.build(surface.triangles, mesh.vertex_count());
    return built;
  }();
};

TEST(PointContact, StartsWhenTheToolEntersAndEndsWhenItLeaves) {
  FrogSurface frog;
  const SurfacePoint target = back_point(frog.surface, frog.rest, 0.0, 0.0);
  const Eigen::Vector3d x = surface_point_position_m(target, frog.surface.triangles, frog.rest);
  const Eigen::Vector3d n = unit_normal(frog.surface.triangles[static_cast<size_t>(target.triangle)], frog.rest);
  const Eigen::Vector3d tangent = n.unitOrthogonal();
  PointContact contact(PointContactSettings{2000.0});

  // Outside: no contact, no force.
  EXPECT_FALSE(contact.update(x + 5e-3 * n, x + 2e-3 * n, frog.rest, frog.bvh));
  EXPECT_EQ(contact.force_on_tool_n(frog.bvh, frog.rest), Eigen::Vector3d::Zero());
  EXPECT_FALSE(contact.spring(frog.bvh).has_value());
  EXPECT_EQ(contact.penetration_depth_m(), 0.0);

  // Crossing in along the normal at the centroid: the proxy is the centroid, 1 mm above the HIP.
  ASSERT_TRUE(contact.update(x + 2e-3 * n, x - 1e-3 * n, frog.rest, frog.bvh));
  EXPECT_EQ(contact.proxy().triangle, target.triangle);
  EXPECT_LE((contact.proxy_position_m() - x).norm(), 1e-15);
  EXPECT_NEAR(contact.penetration_depth_m(), 1e-3, 1e-15);
  // The normal is the smooth one there (interpolated vertex normals), near the face's on the back.
  const Eigen::Vector3d smooth = smooth_normal(target, frog.surface.triangles, frog.adjacency, frog.rest);
  EXPECT_LE((contact.normal() - smooth).norm(), 1e-15);
  EXPECT_GT(smooth.dot(n), std::cos(0.2));
  // The spring pulls the proxy to the HIP along that normal alone: the tool is pushed out along it
  // with k times the depth along it.
  EXPECT_LE((contact.force_on_tool_n(frog.bvh, frog.rest) - 2000.0 * 1e-3 * smooth.dot(n) * smooth).norm(), 1e-12);
  const std::optional<PointSpring> spring = contact.spring(frog.bvh);
  ASSERT_TRUE(spring.has_value());
  EXPECT_EQ(spring->vertices, frog.surface.triangles[static_cast<size_t>(contact.proxy().triangle)]);
  EXPECT_EQ(spring->weights, contact.proxy().barycentric);
  EXPECT_EQ(spring->target_m, contact.hip_m());
  EXPECT_EQ(spring->stiffness_n_per_m, 2000.0);
  EXPECT_EQ(spring->tangent_fraction, contact.settings().spring_tangent_fraction);
  EXPECT_EQ(spring->direction, contact.normal());

  // Sliding deeper and sideways: the proxy is the surface point closest to the HIP.
  const Eigen::Vector3d hip = x - 1.5e-3 * n + 2e-3 * tangent;
  ASSERT_TRUE(contact.update(x - 1e-3 * n, hip, frog.rest, frog.bvh));
  const BruteForce closest = closest_by_brute_force(hip, frog.surface.triangles, frog.rest);
  EXPECT_NEAR(contact.penetration_depth_m(), closest.distance_m, 1e-15);
  EXPECT_LE((contact.proxy_position_m() - closest.point_m).norm(), 1e-12);

  // A NaN tool tip is refused and changes nothing.
  const SurfacePoint proxy = contact.proxy();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(contact.update(hip, Eigen::Vector3d(nan, 0, 0), frog.rest, frog.bvh), std::invalid_argument);
  EXPECT_THROW(contact.update(Eigen::Vector3d(0, nan, 0), hip, frog.rest, frog.bvh), std::invalid_argument);
  EXPECT_TRUE(contact.in_contact());
  EXPECT_EQ(contact.proxy().triangle, proxy.triangle);
  EXPECT_EQ(contact.proxy().barycentric, proxy.barycentric);
  EXPECT_EQ(contact.hip_m(), hip);

  // Back out: the contact ends, the force is gone.
  EXPECT_FALSE(contact.update(hip, x + 0.5e-3 * n, frog.rest, frog.bvh));
  EXPECT_FALSE(contact.in_contact());
  EXPECT_EQ(contact.force_on_tool_n(frog.bvh, frog.rest), Eigen::Vector3d::Zero());

  // A tool that starts inside and moves deeper, or leaves, never entered: no contact.
  EXPECT_FALSE(contact.update(x - 1e-3 * n, x - 2e-3 * n, frog.rest, frog.bvh));
  EXPECT_FALSE(contact.update(x - 1e-3 * n, x + 2e-3 * n, frog.rest, frog.bvh));
  // Release ends a contact at once.
  ASSERT_TRUE(contact.update(x + 2e-3 * n, x - 1e-3 * n, frog.rest, frog.bvh));
  contact.release();
  EXPECT_FALSE(contact.in_contact());
  EXPECT_THROW(PointContact(PointContactSettings{0.0}), ParameterError);
  EXPECT_THROW(PointContact(PointContactSettings{2000.0, 0.0}), ParameterError);
  EXPECT_THROW(PointContact(PointContactSettings{2000.0, 1.5}), ParameterError);
}

TEST(PointContact, TheNearSideHoldsAToolPushedThroughAThinSlab) {
  // A 4 cm x 4 cm slab 1 cm thick; the tool goes from 5 mm above to 5 mm below it in one step.
  const TetMesh mesh = make_box_mesh(4, 4, 1, 0.01);
  const SurfaceMesh surface = extract_surface(mesh);
  const Eigen::VectorXd x = rest_positions(mesh);
  const SurfaceBvh bvh(surface.triangles, x);
  PointContact contact;
  const Eigen::Vector3d above(0.023, 0.026, 0.015), below(0.023, 0.026, -0.005);
  ASSERT_TRUE(contact.update(above, below, x, bvh));
  EXPECT_NEAR(contact.proxy_position_m().z(), 0.01, 1e-15);  // on the top face, not the nearer bottom
  EXPECT_NEAR(contact.normal().z(), 1.0, 1e-12);
  EXPECT_NEAR(contact.penetration_depth_m(), 0.015, 1e-15);
  // Still held from above while it moves sideways underneath.
  ASSERT_TRUE(contact.update(below, below + Eigen::Vector3d(0.005, 0.0, 0.0), x, bvh));
  EXPECT_NEAR(contact.proxy_position_m().z(), 0.01, 1e-15);
  EXPECT_NEAR(contact.proxy_position_m().x(), 0.028, 1e-15);
  // Back above the top face: released.
  EXPECT_FALSE(contact.update(below, above, x, bvh));
}

TEST(SlideToClosestPoint, FindsTheClosestSurfacePointNearTheBack) {
  // Queries up to 1 mm inside and 3 mm sideways of random points on the frog's back (some end up
  // outside where the back curves away), each slide starting at the triangle of that point: the
  // slide ends at the closest point of the whole surface, or at a local minimum within the faceting
  // tolerance, and its pseudo-normal tells inside from outside.
  FrogSurface frog;
  VertexTriangles adjacency;
  adjacency.build(frog.surface.triangles, frog.mesh.vertex_count());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(frog.surface.triangles.size()) - 1);
  int tested = 0, moved = 0, exact = 0;
  double worst_gap_m = 0.0;
  while (tested < 200) {
    const int t = pick(rng);
    const auto& tri = frog.surface.triangles[static_cast<size_t>(t)];
    const Eigen::Vector3d n = unit_normal(tri, frog.rest);
    if (n.z() < 0.8) continue;
    Eigen::Vector3d b(unit(rng), unit(rng), unit(rng));
    b /= b.sum();
    const Eigen::Vector3d p = surface_point_position_m({t, b}, frog.surface.triangles, frog.rest);
    const Eigen::Vector3d sideways =
        n.unitOrthogonal() * (3e-3 * (2 * unit(rng) - 1)) + n.cross(n.unitOrthogonal()) * (3e-3 * (2 * unit(rng) - 1));
    const Eigen::Vector3d query = p - 1e-3 * unit(rng) * n + sideways;
    const SurfaceProjection slide = slide_to_closest_point(query, {t, b}, frog.surface.triangles, adjacency, frog.rest);
    const BruteForce closest = closest_by_brute_force(query, frog.surface.triangles, frog.rest);
    EXPECT_GE(slide.distance_m, closest.distance_m - 1e-15);
    EXPECT_LE(slide.distance_m - closest.distance_m,
              faceting_tolerance_m(slide.distance_m, slide.normal, closest.normal))
        << "query " << query.transpose();
    exact += slide.distance_m - closest.distance_m <= 1e-15;
    worst_gap_m = std::max(worst_gap_m, slide.distance_m - closest.distance_m);
    // The pseudo-normal tells inside from outside (queries within 1 um of the surface aside).
    if (slide.distance_m > 1e-6) {
      EXPECT_EQ((query - slide.position_m).dot(slide.normal) < 0.0, inside_by_tets(query, frog.mesh))
          << "query " << query.transpose();
    }
    moved += slide.steps > 0;
    ++tested;
  }
  std::printf(
      "  %d of %d slides left their start triangle; %d ended on the closest point of the whole surface, "
      "the others at most %.2g m further\n",
      moved, tested, exact, worst_gap_m);
  EXPECT_GT(exact, 9 * tested / 10);
  EXPECT_GT(moved, 20);  // the test exercises the walk, not only the start triangle
  EXPECT_THROW(slide_to_closest_point(Eigen::Vector3d::Zero(), {-1, Eigen::Vector3d::Zero()}, frog.surface.triangles,
                                      adjacency, frog.rest),
               std::invalid_argument);
}

// The sliding contact's direction (point_contact.hpp): continuous where the face normals jump. At
// every edge of the frog's surface, the point a third of the way along it has the same smooth normal
// seen from either triangle (to rounding), while the two face normals differ by up to tens of degrees;
// and on a flat face away from bends it is the face's normal.
TEST(SmoothNormal, IsContinuousOverEdgesAndTheFaceNormalOnAFlat) {
  FrogSurface frog;
  const SurfaceTriangles& triangles = frog.surface.triangles;
  double worst_jump = 0.0;
  double largest_face_jump = 0.0;
  for (int t = 0; t < static_cast<int>(triangles.size()); ++t) {
    for (int a = 0; a < 3; ++a) {
      const int v0 = triangles[static_cast<size_t>(t)][static_cast<size_t>(a)];
      const int v1 = triangles[static_cast<size_t>(t)][static_cast<size_t>((a + 1) % 3)];
      // The other triangle on this edge.
      for (int k = frog.adjacency.begin[static_cast<size_t>(v0)]; k < frog.adjacency.begin[static_cast<size_t>(v0) + 1]; ++k) {
        const int u = frog.adjacency.triangles[static_cast<size_t>(k)];
        const std::array<int, 3>& other = triangles[static_cast<size_t>(u)];
        if (u == t || std::find(other.begin(), other.end(), v1) == other.end()) continue;
        const auto on_edge = [&](int triangle) {
          SurfacePoint point{triangle, Eigen::Vector3d::Zero()};
          const std::array<int, 3>& corners = triangles[static_cast<size_t>(triangle)];
          for (int c = 0; c < 3; ++c) {
            if (corners[static_cast<size_t>(c)] == v0) point.barycentric[c] = 2.0 / 3.0;
            if (corners[static_cast<size_t>(c)] == v1) point.barycentric[c] = 1.0 / 3.0;
          }
          return point;
        };
        const Eigen::Vector3d mine = smooth_normal(on_edge(t), triangles, frog.adjacency, frog.rest);
        const Eigen::Vector3d theirs = smooth_normal(on_edge(u), triangles, frog.adjacency, frog.rest);
        worst_jump = std::max(worst_jump, (mine - theirs).norm());
        largest_face_jump = std::max(largest_face_jump, (unit_normal(triangles[static_cast<size_t>(t)], frog.rest) -
                                                         unit_normal(other, frog.rest))
                                                            .norm());
      }
    }
  }
  EXPECT_LT(worst_jump, 1e-14);
  EXPECT_GT(largest_face_jump, 0.3);

  const TetMesh box = make_box_mesh(4, 4, 2, 0.01);
  const SurfaceMesh surface = extract_surface(box);
  const Eigen::VectorXd rest = rest_positions(box);
  VertexTriangles adjacency;
  adjacency.build(surface.triangles, box.vertex_count());
  int flat = 0;
  for (int t = 0; t < static_cast<int>(surface.triangles.size()); ++t) {
    // A top triangle whose corners are all inside the top face (no corner on the box's rim).
    bool inside = unit_normal(surface.triangles[static_cast<size_t>(t)], rest).z() > 0.99;
    for (const int v : surface.triangles[static_cast<size_t>(t)]) {
      const Eigen::Vector3d x = rest.segment<3>(3 * v);
      inside = inside && x.x() > 1e-9 && x.x() < 0.04 - 1e-9 && x.y() > 1e-9 && x.y() < 0.04 - 1e-9;
    }
    if (!inside) continue;
    ++flat;
    const Eigen::Vector3d n = smooth_normal(SurfacePoint{t, Eigen::Vector3d(0.2, 0.3, 0.5)}, surface.triangles,
                                            adjacency, rest);
    EXPECT_LT((n - Eigen::Vector3d::UnitZ()).norm(), 1e-14);
  }
  EXPECT_GT(flat, 0);
}

TEST(PointContact, TheProxyStaysOnTheSurfaceWhileTheSurfaceMoves) {
  // The frog, held at its tail, sags and swings under gravity (-z); the HIP is kept 0.5 mm inside a
  // material point of its back and circles 1.5 mm around it, so both the surface and the HIP move.
  // The contact is kinematic here (no spring on the body): only the proxy bookkeeping is tested.
  const TetMesh mesh = frog_mesh();
  const SurfaceMesh surface = extract_surface(mesh);
  BodySettings settings = frog_settings(mesh, Hold::hind_feet);
  settings.gravity_m_per_s2 = Eigen::Vector3d(0.0, 0.0, -9.81);
  DeformableBody body(mesh, settings);
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count()), 0.0};
  Eigen::VectorXd x;
  body.positions(state.displacement_m, x);
  SurfaceBvh bvh(surface.triangles, x);
  const SurfacePoint anchor = back_point(surface, x, 0.02, 0.0);
  const Eigen::Vector3d anchor_rest = surface_point_position_m(anchor, surface.triangles, x);

  const auto hip_at = [&](const Eigen::VectorXd& positions, double time_s) {
    const Eigen::Vector3d n = unit_normal(surface.triangles[static_cast<size_t>(anchor.triangle)], positions);
    const Eigen::Vector3d a = n.unitOrthogonal(), b = n.cross(a);
    return Eigen::Vector3d(surface_point_position_m(anchor, surface.triangles, positions) - 0.5e-3 * n +
                           1.5e-3 * (std::cos(40 * time_s) * a + std::sin(40 * time_s) * b));
  };
  PointContact contact;
  Eigen::Vector3d hip_previous =
      hip_at(x, 0.0) + 3e-3 * unit_normal(surface.triangles[static_cast<size_t>(anchor.triangle)], x);
  double largest_motion_m = 0.0, worst_gap_m = 0.0, worst_bary = 0.0;
  int exact = 0;
  const double h = 4e-3;
  const int STEPS = 120;  // 0.48 s
  for (int step = 0; step < STEPS; ++step) {
    body.positions(state.displacement_m, x);
    bvh.refit(x);
    const Eigen::Vector3d hip = hip_at(x, state.time_s);
    ASSERT_TRUE(contact.update(hip_previous, hip, x, bvh)) << "step " << step;
    hip_previous = hip;

    const SurfacePoint& proxy = contact.proxy();
    const auto& tri = surface.triangles[static_cast<size_t>(proxy.triangle)];
    const Eigen::Vector3d by_hand = proxy.barycentric[0] * x.segment<3>(3 * tri[0]) +
                                    proxy.barycentric[1] * x.segment<3>(3 * tri[1]) +
                                    proxy.barycentric[2] * x.segment<3>(3 * tri[2]);
    EXPECT_LE((contact.proxy_position_m() - by_hand).norm(), 1e-15);
    EXPECT_GE(proxy.barycentric.minCoeff(), 0.0);
    EXPECT_LE(proxy.barycentric.maxCoeff(), 1.0);
    worst_bary = std::max(worst_bary, std::abs(proxy.barycentric.sum() - 1.0));
    const BruteForce closest = closest_by_brute_force(hip, surface.triangles, x);
    const double gap_m = contact.penetration_depth_m() - closest.distance_m;
    worst_gap_m = std::max(worst_gap_m, gap_m);
    exact += gap_m <= 1e-15;
    EXPECT_GE(gap_m, -1e-15);
    EXPECT_LE(gap_m, faceting_tolerance_m(contact.penetration_depth_m(), contact.normal(), closest.normal))
        << "step " << step;
    largest_motion_m =
        std::max(largest_motion_m, (surface_point_position_m(anchor, surface.triangles, x) - anchor_rest).norm());

    integrator.step(body, state, h);
  }
  std::printf(
      "  surface moved up to %.1f mm; the proxy was the closest surface point in %d of %d steps, in the "
      "others at most %.1e m further; |sum(b) - 1| <= %.1e\n",
      1e3 * largest_motion_m, exact, STEPS, worst_gap_m, worst_bary);
  EXPECT_LE(worst_bary, 1e-15);
  EXPECT_GT(largest_motion_m, 5e-3);  // the surface did move, by more than the HIP's circle
}

}  // namespace
}  // namespace tissue

namespace tissue {
namespace {

// A pad's samples (point_contact.hpp, "A pad") split the disc into equal areas: their offsets sum to
// zero and their mean squared radius is the disc's, a^2 / 2 (to the rings' placement, 0.3 %).
TEST(PadSamples, CoverTheDiscInEqualAreas) {
  const Eigen::Vector3d u = Eigen::Vector3d(1.0, 1.0, 0.0).normalized();
  const Eigen::Vector3d v = Eigen::Vector3d(-1.0, 1.0, 0.0).normalized();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double squared_radius = 0.0;
  for (int k = 0; k < PAD_SAMPLES; ++k) {
    const Eigen::Vector3d offset = pad_sample_offset(k, u, v);
    EXPECT_LE(offset.norm(), 1.0);
    EXPECT_NEAR(offset.z(), 0.0, 1e-15);
    sum += offset;
    squared_radius += offset.squaredNorm() / PAD_SAMPLES;
  }
  EXPECT_EQ(pad_sample_offset(0, u, v), Eigen::Vector3d::Zero());
  EXPECT_LT(sum.norm(), 1e-14);
  EXPECT_NEAR(squared_radius, 0.5, 0.005);
}

}  // namespace
}  // namespace tissue
