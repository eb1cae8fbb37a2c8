// Conservation and dissipation: a free body conserves linear momentum under backward Euler
// (internal forces sum to zero and K's block rows sum to zero); with Rayleigh damping and no
// load the total energy never increases; with a mass damping alpha per region, a body moving as
// one loses its momentum at the mass-weighted mean alpha.
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/integrate/ida_integrator.hpp"
#include "core/mesh/box_mesh.hpp"
#include "support/two_regions.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace tissue {
namespace {

Eigen::Vector3d momentum(const DeformableBody& body, const Eigen::VectorXd& velocity) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (Eigen::Index row = 0; row < velocity.size() / 3; ++row) {
    p += body.mass_kg()(3 * row) * velocity.segment<3>(3 * row);
  }
  return p;
}

TEST(Conservation, FreeBodyWithoutGravityConservesLinearMomentum) {
  BodySettings settings;
  settings.material = {1.0e5, 0.4, 1000.0};
  settings.gravity_m_per_s2.setZero();
  DeformableBody body(make_box_mesh(8, 3, 2, 0.01), settings);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  DynamicState state;
  state.displacement_m = Eigen::VectorXd::NullaryExpr(body.dof_count(), [&] { return 0.002 * uniform(rng); });
  state.velocity_m_per_s = Eigen::VectorXd::NullaryExpr(body.dof_count(), [&] { return 0.5 * uniform(rng); });
  const Eigen::Vector3d initial = momentum(body, state.velocity_m_per_s);
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  for (int step = 0; step < 100; ++step) integrator.step(body, state, 0.005);
  // Exact in exact arithmetic; the direct solve leaves round-off of ~1e-16 of |M v| per step.
  const double scale = body.total_mass_kg() * 0.5;
  EXPECT_LT((momentum(body, state.velocity_m_per_s) - initial).norm(), 1e-11 * scale);
  // And the body moved: the check is not vacuous.
  EXPECT_GT(state.displacement_m.cwiseAbs().maxCoeff(), 0.01);
}

// A stiff free body of two materials (issue 25), each region with its own mass damping alpha, set
// gliding at 0.1 m/s: internal and beta K forces sum to zero, so its momentum P obeys
// dP/dt = -sum_i alpha_i m_i v_i, and a body that moves as one (v_i = V) slows as
// V' = -alpha_mean V with alpha_mean = sum alpha_t m_t / sum m_t: backward Euler's
// V_n = V_0 / (1 + h alpha_mean)^n, IDA's V_0 exp(-alpha_mean t). The differing alphas strain the
// body only by their force difference over its stiffness, (alpha_b - alpha_a) m V L / (E A) ~ 1e-9 m
// at E = 10 MPa, and beta damps the vibration the start excites (its lowest mode, ~1.6e4 rad/s, at
// beta w^2 / 2 ~ 1e3 1/s), so the unknowns move within 1e-5 of V (measured 7e-7) and backward
// Euler's V is its formula's to 1e-6 (measured 4e-8); IDA's, exp's to 1e-4 (rtol 1e-7 per internal
// step; measured 1.4e-7 with KLU, 1.1e-5 with GMRES, whose linear tolerance is looser). With the
// regions' alphas ignored the body would slow at the body's alpha, 1 1/s: V would end 80 % higher.
TEST(Conservation, ABodyOfTwoDampingsSlowsAtTheirMassWeightedMeanAlpha) {
  const TetMesh mesh =
      test::split_at_x(make_box_mesh(4, 2, 2, 0.005), 0.01, {"skin", std::nullopt}, {"tumour", std::nullopt});
  BodySettings settings;
  settings.material = {1.0e7, 0.4, 1000.0};
  settings.damping = {1.0, 1.0e-5};
  settings.gravity_m_per_s2.setZero();
  Material skin = settings.material, tumour{2.0e7, 0.45, 1500.0};
  skin.mass_damping_per_s = 2.0;
  tumour.mass_damping_per_s = 20.0;
  settings.region_materials = {{"skin", skin}, {"tumour", tumour}};
  // Half the volume each (x below and above 1 cm): alpha_mean = (2 * 1000 + 20 * 1500) / 2500 = 12.8 1/s.
  const double alpha_mean_per_s = (2.0 * 1000.0 + 20.0 * 1500.0) / 2500.0;
  const double step_s = 0.002, speed_m_per_s = 0.1;
  const int steps = 25;

  const auto mean_velocity = [](const DeformableBody& body, const DynamicState& state) {
    double momentum = 0.0;
    for (Eigen::Index row = 0; row < state.velocity_m_per_s.size() / 3; ++row) {
      momentum += body.mass_kg()(3 * row) * state.velocity_m_per_s(3 * row);
    }
    return momentum / body.total_mass_kg();
  };
  const auto run = [&](Integrator& integrator) {
    DeformableBody body(mesh, settings);
    EXPECT_EQ(body.region_mass_damping_per_s(), (std::vector<double>{2.0, 20.0}));
    DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count()), 0.0};
    for (Eigen::Index row = 0; row < body.dof_count() / 3; ++row) state.velocity_m_per_s(3 * row) = speed_m_per_s;
    for (int step = 0; step < steps; ++step) integrator.step(body, state, step_s);
    // It moved as one: every unknown within the tolerance of the mean.
    const double mean = mean_velocity(body, state);
    for (Eigen::Index row = 0; row < body.dof_count() / 3; ++row) {
      EXPECT_NEAR(state.velocity_m_per_s(3 * row), mean, 1e-5 * mean);
    }
    return mean;
  };

  BackwardEuler backward_euler(std::make_unique<CholmodSolver>());
  EXPECT_NEAR(run(backward_euler), speed_m_per_s / std::pow(1.0 + step_s * alpha_mean_per_s, steps),
              1e-6 * speed_m_per_s);
  for (const IdaLinearSolverKind solver : {IdaLinearSolverKind::klu, IdaLinearSolverKind::krylov}) {
    SCOPED_TRACE(std::string(to_string(solver)));
    IdaSettings ida;
    ida.relative_tolerance = 1e-7;
    ida.absolute_tolerance = 1e-10;
    ida.linear_solver = solver;
    IdaIntegrator integrator(ida);
    EXPECT_NEAR(run(integrator), speed_m_per_s * std::exp(-alpha_mean_per_s * steps * step_s), 1e-4 * speed_m_per_s);
  }
}

TEST(Conservation, DampedUnloadedEnergyNeverIncreases) {
  BodySettings settings;
  settings.material = {1.0e5, 0.4, 1000.0};
  settings.damping = {0.5, 0.002};
  settings.gravity_m_per_s2.setZero();
  TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  settings.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  DeformableBody body(std::move(mesh), settings);
  // Start bent: a tip-loaded cantilever shape u_y = c (x/L)^2, released from rest.
  DynamicState state;
  state.displacement_m.setZero(body.dof_count());
  state.velocity_m_per_s.setZero(body.dof_count());
  for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
    const double x =
        body.mesh().rest_positions_m[static_cast<size_t>(body.dofs().row_vertex[static_cast<size_t>(row)])].x();
    state.displacement_m(3 * row + 1) = 0.03 * (x / 0.1) * (x / 0.1);
  }
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  double energy = body.kinetic_energy_j(state.velocity_m_per_s) + body.elastic_energy_j(state.displacement_m);
  const double initial = energy;
  for (int step = 0; step < 400; ++step) {
    integrator.step(body, state, 0.002);
    const double next = body.kinetic_energy_j(state.velocity_m_per_s) + body.elastic_energy_j(state.displacement_m);
    // Backward Euler dissipates (for a linear system E_{n+1} - E_n = -h v^T D v - 1/2 |dv|_M^2 -
    // 1/2 |du|_K^2 <= 0); the co-rotational linearisation may add round-off-sized wiggles only.
    EXPECT_LE(next, energy * (1.0 + 1e-9)) << "step " << step;
    energy = next;
  }
  EXPECT_LT(energy, 0.5 * initial);  // and it really did dissipate
}

}  // namespace
}  // namespace tissue
