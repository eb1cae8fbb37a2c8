// The contact in the simulation loop: the probe pressed 1 mm into the frog and held, with the
// dynamic simulation (backward Euler + CHOLMOD, Rayleigh damping, the god-object's spring in the
// implicit step) run until it settles, gives the tool force of the quasi-static frictionless poke
// of the full model, up to the compliance of the contact spring.
#include "core/contact/contact_stiffness.hpp"
#include "core/contact/point_contact.hpp"
#include "core/contact/quasi_static_poke.hpp"
#include "core/integrate/backward_euler.hpp"

#include "contact/frog_scene.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

namespace tissue {
namespace {

using namespace contact_test;

struct SettledPress {
  Eigen::Vector3d force_on_tool_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d proxy_m = Eigen::Vector3d::Zero();  // the proxy's material point, settled
  int steps = 0;
  bool settled = false;
};

// Tissue's loop: positions -> refit -> god-object update -> spring into the body -> one implicit step.
SettledPress press_and_hold(DeformableBody& body, const SurfaceMesh& surface, double spring_n_per_m,
                            const Eigen::Vector3d& hip_outside, const Eigen::Vector3d& hip) {
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count()), 0.0};
  Eigen::VectorXd x;
  body.positions(state.displacement_m, x);
  SurfaceBvh bvh(surface.triangles, x);
  const double step_size_s = 1e-2;
  PointContact contact(
      PointContactSettings{spring_n_per_m, undamped_tangent_fraction(step_size_s, body.stiffness_damping_s())});
  PointSpringTerm spring_term;
  body.attach(spring_term);
  Eigen::Vector3d hip_previous = hip_outside;
  SettledPress press;
  int quiet_steps = 0;
  Eigen::Vector3d previous_force = Eigen::Vector3d::Zero();
  for (press.steps = 0; press.steps < 4000 && quiet_steps < 10; ++press.steps) {
    body.positions(state.displacement_m, x);
    bvh.refit(x);
    EXPECT_TRUE(contact.update(hip_previous, hip, x, bvh));
    hip_previous = hip;
    contact.apply(bvh, spring_term, body.term_layout());
    integrator.step(body, state, step_size_s);
    body.positions(state.displacement_m, x);
    press.force_on_tool_n = contact.force_on_tool_n(bvh, x);
    press.proxy_m = surface_point_position_m(contact.proxy(), surface.triangles, x);
    // Settled: the force changes by less than 1e-10 of itself per step, ten steps in a row.
    quiet_steps =
        (press.force_on_tool_n - previous_force).norm() <= 1e-10 * press.force_on_tool_n.norm() ? quiet_steps + 1 : 0;
    previous_force = press.force_on_tool_n;
  }
  press.settled = quiet_steps >= 10;
  body.detach(spring_term);
  return press;
}

TEST(ContactDynamics, PressingTheProbeGivesTheQuasiStaticReactionOfTheFullModel) {
  const TetMesh mesh = frog_mesh();
  const SurfaceMesh surface = extract_surface(mesh);
  BodySettings settings = frog_settings(mesh);
  settings.damping = RayleighDamping{10.0, 5e-3};
  DeformableBody body(mesh, settings);
  const Eigen::VectorXd rest = rest_positions(mesh);
  // A tenth of the default spring factor: with the isotropic contact spring a tangential load
  // relaxes by k_t / k per step (point_contact.hpp), so the default would need ~10x the steps.
  const double factor = 10.0;
  const double spring = recommended_contact_spring_stiffness_n_per_m(body, surface, factor);

  for (const SurfacePoint& point : back_points(surface, rest)) {
    const Eigen::Vector3d x = surface_point_position_m(point, surface.triangles, rest);
    const Eigen::Vector3d n = unit_normal(surface.triangles[static_cast<size_t>(point.triangle)], rest);
    const double depth_m = 1e-3;
    const Eigen::Vector3d hip = x - depth_m * n;

    const SettledPress press = press_and_hold(body, surface, spring, x + 2e-3 * n, hip);
    ASSERT_TRUE(press.settled) << "no rest after " << press.steps << " steps";
    const QuasiStaticPoke poke = quasi_static_poke(body, surface.triangles, point, hip);
    ASSERT_TRUE(poke.converged);

    // The spring leaves the surface |f| / k short of the HIP: the dynamic force is that of a poke
    // |f| / k shallower, a relative deficit ~ k_n / k with k_n = |f_qs| / d the poke's secant
    // stiffness. The slope at d differs from the secant by O(d / h) (~30 % for 1 mm on 3 mm
    // elements), hence the factor 1.5.
    const double secant_n_per_m = poke.force_on_tool_n.norm() / depth_m;
    const double tolerance = 1.5 * secant_n_per_m / spring;
    const double difference = (press.force_on_tool_n - poke.force_on_tool_n).norm() / poke.force_on_tool_n.norm();
    EXPECT_LE(difference, tolerance);
    EXPECT_LE(secant_n_per_m / spring, 2.2 / factor);  // the recommended spring's bound (contact_stiffness.hpp)

    // Where the spring left the surface, the quasi-static poke gives the dynamic force exactly (to
    // the settling and slide tolerances): the contact model is the full model's frictionless poke.
    const QuasiStaticPoke at_proxy = quasi_static_poke(body, surface.triangles, point, press.proxy_m);
    ASSERT_TRUE(at_proxy.converged);
    const double consistency =
        (press.force_on_tool_n - at_proxy.force_on_tool_n).norm() / at_proxy.force_on_tool_n.norm();
    EXPECT_LE(consistency, 1e-6);
    std::printf(
        "  triangle %d: dynamic |f| %.6g N after %d steps, quasi-static %.6g N: difference %.2e "
        "(tolerance %.2e, k_n/k %.2e); at the settled proxy %.2e\n",
        point.triangle, press.force_on_tool_n.norm(), press.steps, poke.force_on_tool_n.norm(), difference, tolerance,
        secant_n_per_m / spring, consistency);
  }
}

}  // namespace
}  // namespace tissue
