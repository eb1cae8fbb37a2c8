// Tests of the quasi-static reference: at a finite (nonlinear) depth the bonded reaction is the
// gradient of the constrained minimum energy; the frictionless reaction is normal to the deformed
// surface, its energy is no higher than the bonded one, and in the linear limit it is the
// frictionless normal stiffness times the depth; invalid requests are refused.
#include "core/contact/contact_stiffness.hpp"
#include "core/contact/quasi_static_poke.hpp"

#include "contact/frog_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace tissue {
namespace {

using namespace contact_test;

struct Frog {
  TetMesh mesh = frog_mesh();
  SurfaceMesh surface = extract_surface(mesh);
  DeformableBody body{mesh, frog_settings(mesh)};
  Eigen::VectorXd rest = rest_positions(mesh);

  Eigen::Vector3d position(const SurfacePoint& point) const {
    return surface_point_position_m(point, surface.triangles, rest);
  }
  Eigen::Vector3d normal(const SurfacePoint& point) const {
    return unit_normal(surface.triangles[static_cast<size_t>(point.triangle)], rest);
  }
  QuasiStaticPoke poke(const SurfacePoint& point, const Eigen::Vector3d& target, PokeFriction friction,
                       const Eigen::VectorXd& start = Eigen::VectorXd()) {
    QuasiStaticPokeSettings settings;
    settings.friction = friction;
    return quasi_static_poke(body, surface.triangles, point, target, settings, start);
  }
};

TEST(QuasiStaticPoke, BondedReactionIsTheGradientOfTheConstrainedMinimumEnergy) {
  // E*(t) = min { E(u) : x_s(u) = t } has dE*/dt = lambda (the multiplier is the force on the body).
  // At 1 mm the co-rotational response is nonlinear, so this checks the Newton solution itself.
  Frog frog;
  const SurfacePoint point = back_points(frog.surface, frog.rest)[0];
  const Eigen::Vector3d target = frog.position(point) - 1e-3 * frog.normal(point);
  const QuasiStaticPoke centre = frog.poke(point, target, PokeFriction::bonded);
  ASSERT_TRUE(centre.converged);
  EXPECT_LE(centre.force_residual, 1e-10);
  const Eigen::Vector3d lambda = -centre.force_on_tool_n;

  const double eps_m = 1e-6;  // truncation (eps / h)^2 ~ 1e-7 for h ~ 3 mm elements
  Eigen::Vector3d gradient;
  for (int axis = 0; axis < 3; ++axis) {
    double energy[2];
    for (int side = 0; side < 2; ++side) {
      const Eigen::Vector3d t = target + (side == 0 ? eps_m : -eps_m) * Eigen::Vector3d::Unit(axis);
      const QuasiStaticPoke poke = frog.poke(point, t, PokeFriction::bonded, centre.displacement_m);
      ASSERT_TRUE(poke.converged);
      energy[side] = frog.body.elastic_energy_j(poke.displacement_m);
    }
    gradient[axis] = (energy[0] - energy[1]) / (2 * eps_m);
  }
  std::printf("  1 mm bonded poke: reaction (%.6g, %.6g, %.6g) N, energy gradient error %.2e, %d Newton iterations\n",
              lambda.x(), lambda.y(), lambda.z(), (gradient - lambda).norm() / lambda.norm(), centre.newton_iterations);
  EXPECT_LE((gradient - lambda).norm(), 1e-6 * lambda.norm());
  // The held point is at the target.
  Eigen::VectorXd positions;
  frog.body.positions(centre.displacement_m, positions);
  EXPECT_LE((surface_point_position_m(point, frog.surface.triangles, positions) - target).norm(), 1e-15);
}

TEST(QuasiStaticPoke, FrictionlessReactionIsNormalToTheDeformedSurface) {
  Frog frog;
  for (const SurfacePoint& point : back_points(frog.surface, frog.rest)) {
    const Eigen::Vector3d target = frog.position(point) - 1e-3 * frog.normal(point);
    const QuasiStaticPoke bonded = frog.poke(point, target, PokeFriction::bonded);
    const QuasiStaticPoke frictionless = frog.poke(point, target, PokeFriction::frictionless);
    ASSERT_TRUE(bonded.converged);
    ASSERT_TRUE(frictionless.converged);
    EXPECT_LE(frictionless.tangential_residual, 1e-9);
    EXPECT_GT(frictionless.force_on_tool_n.dot(frictionless.normal), 0.0);  // pushes the tool out
    Eigen::VectorXd positions;
    frog.body.positions(frictionless.displacement_m, positions);
    EXPECT_LE((surface_point_position_m(frictionless.contact, frog.surface.triangles, positions) - target).norm(),
              1e-15);
    // Frictionless minimises the energy over the held point too: never above the bonded minimum.
    const double e_bonded = frog.body.elastic_energy_j(bonded.displacement_m);
    const double e_frictionless = frog.body.elastic_energy_j(frictionless.displacement_m);
    EXPECT_LE(e_frictionless, e_bonded * (1 + 1e-12));
    std::printf(
        "  triangle %d, 1 mm: bonded |f| %.5g N (tangential %.3f), frictionless |f| %.5g N after %d slides; "
        "energy %.5g vs %.5g mJ\n",
        point.triangle, bonded.force_on_tool_n.norm(), bonded.tangential_residual, frictionless.force_on_tool_n.norm(),
        frictionless.slide_iterations, 1e3 * e_bonded, 1e3 * e_frictionless);
  }
}

TEST(QuasiStaticPoke, FrictionlessLinearLimitIsTheFrictionlessNormalStiffness) {
  // f = m / (n^T K_c^-1 m) d for a push of depth d along the face normal n as d -> 0, m the smooth
  // normal the reaction is along (the held point moves by K_c^-1 f = -d n + t, t in the face's
  // plane); central differences cancel the O(d^2) term, leaving (d / h)^2 ~ 1e-7 and the slide
  // tolerance.
  Frog frog;
  const SurfacePoint point = back_points(frog.surface, frog.rest)[1];
  const Eigen::Vector3d n = frog.normal(point);
  const double depth_m = 1e-6;
  const QuasiStaticPoke in = frog.poke(point, frog.position(point) - depth_m * n, PokeFriction::frictionless);
  const QuasiStaticPoke out = frog.poke(point, frog.position(point) + depth_m * n, PokeFriction::frictionless);
  ASSERT_TRUE(in.converged);
  ASSERT_TRUE(out.converged);
  const Eigen::Vector3d slope = (in.force_on_tool_n - out.force_on_tool_n) / (2 * depth_m);
  // K_c at rest, from the rest tangent.
  Eigen::VectorXd force, diagonal;
  frog.body.evaluate(Eigen::VectorXd::Zero(frog.body.dof_count()), force, true);
  EffectiveContactStiffness effective;
  effective.factorize(static_contact_system(frog.body.tangent(), diagonal));
  const Eigen::Matrix3d k_c = *effective.stiffness_n_per_m(contact_interpolation(
      frog.body.dofs(), frog.surface.triangles[static_cast<size_t>(point.triangle)], point.barycentric));
  VertexTriangles adjacency;
  adjacency.build(frog.surface.triangles, frog.body.mesh().vertex_count());
  const Eigen::Vector3d m = smooth_normal(point, frog.surface.triangles, adjacency, frog.rest);
  const Eigen::Vector3d expected = m / n.dot(k_c.ldlt().solve(m));
  std::printf("  frictionless slope %.6g N/m (bonded n.K_c.n %.6g N/m), error %.2e\n", slope.norm(),
              normal_stiffness_n_per_m(k_c, n), (slope - expected).norm() / expected.norm());
  EXPECT_LE((slope - expected).norm(), 1e-6 * expected.norm());
}

TEST(QuasiStaticPoke, RefusesWhatHasNoAnswer) {
  Frog frog;
  const SurfacePoint point = back_points(frog.surface, frog.rest)[0];
  const Eigen::Vector3d target = frog.position(point);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(frog.poke(point, Eigen::Vector3d(nan, 0, 0), PokeFriction::frictionless), std::invalid_argument);
  EXPECT_THROW(frog.poke(SurfacePoint{-1, point.barycentric}, target, PokeFriction::bonded), std::invalid_argument);
  EXPECT_THROW(frog.poke(point, target, PokeFriction::bonded, Eigen::VectorXd::Zero(5)), std::invalid_argument);

  BodySettings settings = frog_settings(frog.mesh);
  settings.fixed_vertices.clear();
  DeformableBody free_body(frog.mesh, settings);
  EXPECT_THROW(quasi_static_poke(free_body, frog.surface.triangles, point, target), std::invalid_argument);

  // Pushing the point to where it is: no force, nothing moves.
  const QuasiStaticPoke none = frog.poke(point, target, PokeFriction::frictionless);
  EXPECT_TRUE(none.converged);
  EXPECT_EQ(none.force_on_tool_n.norm(), 0.0);
  EXPECT_EQ(none.displacement_m.norm(), 0.0);
}

TEST(QuasiStaticPoke, LeavesTheBodysContactSpringAsItWas) {
  Frog frog;
  const SurfacePoint point = back_points(frog.surface, frog.rest)[0];
  const PointSpring spring{frog.surface.triangles[static_cast<size_t>(point.triangle)], point.barycentric,
                           frog.position(point), 123.0};
  PointSpringTerm spring_term;
  frog.body.attach(spring_term);
  spring_term.set(spring, frog.body.term_layout());
  const QuasiStaticPoke poke = frog.poke(point, frog.position(point) - 1e-4 * frog.normal(point), PokeFriction::bonded);
  EXPECT_TRUE(poke.converged);
  ASSERT_EQ(frog.body.force_terms(), std::vector<ForceTerm*>{&spring_term}) << "the spring is attached again";
  ASSERT_TRUE(spring_term.spring().has_value());
  EXPECT_EQ(spring_term.spring()->stiffness_n_per_m, 123.0);
  EXPECT_EQ(spring_term.spring()->vertices, spring.vertices);
}

}  // namespace
}  // namespace tissue
