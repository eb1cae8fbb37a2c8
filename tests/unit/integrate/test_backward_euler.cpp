// Backward Euler through the Integrator/DynamicsModel contract, on a model with an exact solution:
// independent undamped oscillators M a + k u = 0 (one 3x3 block per mass, K = k I).
#include "core/integrate/backward_euler.hpp"
#include "core/system/rayleigh_damping.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace tissue {
namespace {

class Oscillators final : public DynamicsModel {
 public:
  // The tangent holds tangent_fraction k (1: the derivative of the force k u).
  Oscillators(int count, double mass_kg, double stiffness_n_per_m, RayleighDamping damping,
              double tangent_fraction = 1.0)
      : m_stiffness_n_per_m(stiffness_n_per_m),
        m_tangent_fraction(tangent_fraction),
        m_damping(damping),
        m_mass(Eigen::VectorXd::Constant(3 * count, mass_kg)),
        m_mass_damping(damping.mass_damping_per_s * m_mass),
        m_external(Eigen::VectorXd::Zero(3 * count)),
        m_tangent(diagonal_pattern(count)) {}

  int dof_count() const override { return static_cast<int>(m_mass.size()); }
  const Eigen::VectorXd& mass_kg() const override { return m_mass; }
  const Eigen::VectorXd& mass_damping_kg_per_s() const override { return m_mass_damping; }
  double stiffness_damping_s() const override { return m_damping.stiffness_damping_s; }
  const Eigen::VectorXd& external_force_n() const override { return m_external; }
  void evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f, bool update_tangent) override {
    f = m_stiffness_n_per_m * u;
    if (!update_tangent) return;
    for (int row = 0; row < m_tangent.block_rows(); ++row) {
      m_tangent.block(m_tangent.find_slot(row, row)) =
          m_tangent_fraction * m_stiffness_n_per_m * Eigen::Matrix3d::Identity();
    }
  }
  const BlockSparseMatrix& tangent() const override { return m_tangent; }

 private:
  static std::vector<std::vector<int>> diagonal_pattern(int count) {
    std::vector<std::vector<int>> pattern(static_cast<size_t>(count));
    for (int i = 0; i < count; ++i) pattern[static_cast<size_t>(i)] = {i};
    return pattern;
  }
  double m_stiffness_n_per_m;
  double m_tangent_fraction;
  RayleighDamping m_damping;
  Eigen::VectorXd m_mass, m_mass_damping, m_external;
  BlockSparseMatrix m_tangent;
};

// Displacement error at t = 1 s of BE against x0 cos(w t), for a given step.
double error_at_one_second(double step_size_s) {
  Oscillators model(2, 0.5, 2.0, {});  // w = 2 rad/s
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  DynamicState state{Eigen::VectorXd::Constant(6, 0.01), Eigen::VectorXd::Zero(6), 0.0};
  const int steps = static_cast<int>(std::lround(1.0 / step_size_s));
  for (int i = 0; i < steps; ++i) integrator.step(model, state, step_size_s);
  return std::abs(state.displacement_m(0) - 0.01 * std::cos(2.0));
}

TEST(BackwardEuler, IsFirstOrderAccurate) {
  // Global error of a first-order method: e(h) ~ C h, so e(h) / e(h/2) -> 2 as h -> 0.
  const double e1 = error_at_one_second(1.0 / 200);
  const double e2 = error_at_one_second(1.0 / 400);
  const double e3 = error_at_one_second(1.0 / 800);
  EXPECT_NEAR(std::log2(e1 / e2), 1.0, 0.05);
  EXPECT_NEAR(std::log2(e2 / e3), 1.0, 0.03);
}

TEST(BackwardEuler, DampsAnUndampedOscillatorAtTheKnownRate) {
  // For M a + k u = 0, one BE step multiplies the amplitude of the mode by 1/sqrt(1 + (w h)^2)
  // (the modulus of the eigenvalues of the BE amplification matrix).
  const double h = 0.05;
  const double w = 2.0;
  Oscillators model(1, 0.5, 2.0, {});
  BackwardEuler integrator(std::make_unique<PcgSolver>(PcgSolver::Settings{1e-14, 100}));
  DynamicState state{Eigen::VectorXd::Constant(3, 1.0), Eigen::VectorXd::Zero(3), 0.0};
  const int steps = 40;
  for (int i = 0; i < steps; ++i) integrator.step(model, state, h);
  // The amplitude measured as sqrt(u^2 + (v/w)^2).
  const double amplitude = std::hypot(state.displacement_m(0), state.velocity_m_per_s(0) / w);
  const double expected = std::pow(1.0 + (w * h) * (w * h), -0.5 * steps);
  EXPECT_NEAR(amplitude, expected, 1e-10);
}

TEST(BackwardEuler, AStiffnessEnteredWithTheUndampedFractionIsNotRayleighDamped) {
  // The god-object's contact spring: beta = 0.01 s would damp it like tissue; entered in the tangent
  // with the share h / (h + beta) it is stepped exactly as the undamped oscillator above
  // (amplitude factor 1/sqrt(1 + (w h)^2) per step), whatever beta.
  const double h = 0.05;
  const double w = 2.0;
  const int steps = 40;
  const auto amplitude = [&](double beta, double tangent_fraction) {
    Oscillators model(1, 0.5, 2.0, {0.0, beta}, tangent_fraction);
    BackwardEuler integrator(std::make_unique<CholmodSolver>());
    DynamicState state{Eigen::VectorXd::Constant(3, 1.0), Eigen::VectorXd::Zero(3), 0.0};
    for (int i = 0; i < steps; ++i) integrator.step(model, state, h);
    return std::hypot(state.displacement_m(0), state.velocity_m_per_s(0) / w);
  };
  const double undamped = std::pow(1.0 + (w * h) * (w * h), -0.5 * steps);
  for (const double beta : {0.01, 0.1, 1.0}) {
    EXPECT_NEAR(amplitude(beta, undamped_tangent_fraction(h, beta)), undamped, 1e-12) << beta;
  }
  EXPECT_LT(amplitude(1.0, 1.0), 0.5 * undamped);  // entered whole, it is damped
  EXPECT_EQ(undamped_tangent_fraction(h, 0.0), 1.0);
  EXPECT_THROW((void)undamped_tangent_fraction(0.0, 0.01), ParameterError);
  EXPECT_THROW((void)undamped_tangent_fraction(h, -1.0), ParameterError);
}

TEST(BackwardEuler, RefusesBadStepsAndLeavesTheStateUnchanged) {
  Oscillators model(1, 1.0, 1.0, {});
  BackwardEuler integrator(std::make_unique<CholmodSolver>());
  DynamicState state{Eigen::VectorXd::Constant(3, 1.0), Eigen::VectorXd::Zero(3), 0.0};
  EXPECT_THROW(integrator.step(model, state, 0.0), IntegrationError);
  EXPECT_THROW(integrator.step(model, state, std::nan("")), IntegrationError);
  EXPECT_EQ(state.displacement_m, Eigen::VectorXd::Constant(3, 1.0));
  EXPECT_EQ(state.time_s, 0.0);
  // An indefinite system (negative stiffness large enough to beat the mass) fails in CHOLMOD.
  Oscillators unstable(1, 1.0, -1e6, {});
  EXPECT_THROW(integrator.step(unstable, state, 0.1), IntegrationError);
  EXPECT_EQ(state.displacement_m, Eigen::VectorXd::Constant(3, 1.0));
}

}  // namespace
}  // namespace tissue
