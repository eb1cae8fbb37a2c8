// The step's start evaluated ahead (DynamicsModel::evaluate_ahead): backward Euler's energy guard
// evaluates the end of a step that turns elements, and the next step takes that evaluation instead of
// making its own. What a user must not see: any difference. The steps are bitwise those of a model
// that declines, a state saved between the evaluation and its step continues bitwise in a fresh body,
// and an evaluation made before the tool's spring moved is not taken.
#include "core/contact/point_spring.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/solve/linear_solver.hpp"
#include "fem/xfem_test_helpers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

namespace tissue {
namespace {

// A body behind the integrator's interface that may decline evaluations ahead, and counts the ones
// taken.
class Forwarding final : public DynamicsModel {
 public:
  Forwarding(DeformableBody& body, bool ahead) : m_body(body), m_ahead(ahead) {}
  [[nodiscard]] int dof_count() const override { return m_body.dof_count(); }
  [[nodiscard]] const Eigen::VectorXd& mass_kg() const override { return m_body.mass_kg(); }
  [[nodiscard]] const Eigen::VectorXd& mass_damping_kg_per_s() const override { return m_body.mass_damping_kg_per_s(); }
  [[nodiscard]] double stiffness_damping_s() const override { return m_body.stiffness_damping_s(); }
  [[nodiscard]] const Eigen::VectorXd& external_force_n() const override { return m_body.external_force_n(); }
  void evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& f, bool tangent) override { m_body.evaluate(u, f, tangent); }
  void lend_work_team(WorkTeam* team) override { m_body.lend_work_team(team); }
  [[nodiscard]] const BlockSparseMatrix& tangent() const override { return m_body.tangent(); }
  [[nodiscard]] const std::vector<Eigen::Matrix3d>* block_frames() const override { return m_body.block_frames(); }
  [[nodiscard]] const std::vector<Eigen::Vector3d>* block_positions(const Eigen::VectorXd& u) const override {
    return m_body.block_positions(u);
  }
  [[nodiscard]] double largest_turn_rad(const Eigen::VectorXd& increment, double resolution_rad) const override {
    return m_body.largest_turn_rad(increment, resolution_rad);
  }
  [[nodiscard]] double potential_energy_j(const Eigen::VectorXd& u) override {
    ++m_potential_passes;
    return m_body.potential_energy_j(u);
  }
  [[nodiscard]] double kept_potential_energy_j(const Eigen::VectorXd& u) const override {
    return m_ahead ? m_body.kept_potential_energy_j(u) : std::numeric_limits<double>::quiet_NaN();
  }
  void evaluate_with_potential(const Eigen::VectorXd& u, Eigen::VectorXd& f, bool tangent) override {
    m_body.evaluate_with_potential(u, f, tangent);
  }
  [[nodiscard]] double potential_energy_at_last_evaluate_j() const override {
    return m_body.potential_energy_at_last_evaluate_j();
  }
  bool evaluate_ahead(const Eigen::VectorXd& u, Eigen::VectorXd& f) override {
    const bool made = m_ahead && m_body.evaluate_ahead(u, f);
    m_made += made ? 1 : 0;
    return made;
  }
  bool take_evaluation_ahead(const Eigen::VectorXd& u) override {
    const bool taken = m_body.take_evaluation_ahead(u);
    m_taken += taken ? 1 : 0;
    return taken;
  }
  [[nodiscard]] int taken() const { return m_taken; }
  [[nodiscard]] int made() const { return m_made; }
  [[nodiscard]] int potential_passes() const { return m_potential_passes; }

 private:
  DeformableBody& m_body;
  bool m_ahead;
  int m_taken = 0;
  int m_made = 0;
  int m_potential_passes = 0;
};

const TetMesh& beam() {
  static const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  return mesh;
}

BodySettings cantilever() {
  BodySettings settings;
  settings.material = Material{1.0e5, 0.4, 1000.0};
  settings.damping = RayleighDamping{0.5, 1e-3};
  settings.gravity_m_per_s2 = {0.0, 0.0, -9.81};
  settings.fixed_vertices = vertices_at_minimum(beam(), 0, 0.0);
  return settings;
}

// The beam's swing: backward Euler with the default protections and Jacobi PCG to 1e-8.
struct Swing {
  DeformableBody body{beam(), cantilever()};
  PointSpringTerm spring;  // attached, idle until set
  Forwarding model;
  BackwardEuler integrator{std::make_unique<PcgSolver>(PcgSolver::Settings{1e-8, 10000})};
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count()), 0.0};
  double step_size_s = 0.01;
  explicit Swing(bool ahead) : model(body, ahead) { body.attach(spring); }
  // Linearized at the predicted end (the products' step): nothing is evaluated ahead; the guard's
  // end potential is kept for the next step's start.
  Swing(bool keeps, bool predicted) : Swing(keeps) {
    BackwardEuler::Settings settings;
    settings.newton.linearize_at_predicted_end = predicted;
    integrator = BackwardEuler(std::make_unique<PcgSolver>(PcgSolver::Settings{1e-8, 10000}), settings);
  }
  StepReport step() { return integrator.step(model, state, step_size_s); }
};

bool bitwise_equal(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

// The tool's spring on the free end's last tet, pulling it 1 cm aside.
PointSpring pull_on_the_tip() {
  const Tet& tet = beam().tets.back();
  PointSpring spring;
  spring.vertices = {tet[0], tet[1], tet[2]};
  spring.target_m = Eigen::Vector3d::Zero();
  for (const int v : spring.vertices) spring.target_m += beam().rest_positions_m[static_cast<size_t>(v)] / 3.0;
  spring.target_m.y() += 0.01;
  spring.stiffness_n_per_m = 50.0;
  return spring;
}

TEST(EvaluationAhead, TheStepsAreBitwiseThoseOfAModelThatDeclines) {
  // The beam released swings and sags: the first steps turn its elements past the guard's 0.005 rad.
  // At step 30 the tool's spring takes the tip: the evaluation the guard made before is not taken
  // (the spring was set since), and none is made while the spring pulls. Before the spring moved
  // the revision on, the step after it took the evaluation without the spring and strayed.
  Swing ahead(true), declines(false);
  int guarded = 0;
  for (int n = 0; n < 45; ++n) {
    if (n == 30) {
      for (Swing* swing : {&ahead, &declines}) swing->spring.set(pull_on_the_tip(), swing->body.term_layout());
    }
    const int taken_before = ahead.model.taken();
    const StepReport report = ahead.step();
    declines.step();
    guarded += report.guard_s > 0.0 ? 1 : 0;
    if (n == 30) {
      EXPECT_EQ(ahead.model.taken(), taken_before) << "taken although the spring was set since";
    }
    ASSERT_TRUE(bitwise_equal(ahead.state.displacement_m, declines.state.displacement_m)) << "step " << n;
    ASSERT_TRUE(bitwise_equal(ahead.state.velocity_m_per_s, declines.state.velocity_m_per_s)) << "step " << n;
  }
  EXPECT_GE(guarded, 10);
  EXPECT_GE(ahead.model.taken(), 8);  // the starts evaluated ahead and taken
  EXPECT_EQ(declines.model.taken(), 0);
  // The spring did pull: the tip moved toward +y.
  EXPECT_GT(ahead.spring.force_on_body_n().y(), 0.0);
}

TEST(EvaluationAhead, AfterANewtonCorrectionTheStepsAreBitwiseThoseOfAModelThatDeclines) {
  // 50 ms steps turn the released beam's elements past the 0.05 rad trigger: each corrected step's
  // last line search evaluates its first trial ahead, and the next step takes it when the search did.
  Swing ahead(true), declines(false);
  int corrected = 0, taken_after_corrected = 0;
  bool last_corrected = false;
  for (int n = 0; n < 30; ++n) {
    ahead.step_size_s = declines.step_size_s = 0.05;
    const int taken_before = ahead.model.taken();
    const StepReport report = ahead.step();
    declines.step();
    taken_after_corrected += last_corrected && ahead.model.taken() > taken_before ? 1 : 0;
    last_corrected = report.newton_iterations > 0;
    corrected += last_corrected ? 1 : 0;
    ASSERT_TRUE(bitwise_equal(ahead.state.displacement_m, declines.state.displacement_m)) << "step " << n;
    ASSERT_TRUE(bitwise_equal(ahead.state.velocity_m_per_s, declines.state.velocity_m_per_s)) << "step " << n;
  }
  std::printf("  %d corrected steps, %d of the steps after them took the start evaluated ahead\n", corrected,
              taken_after_corrected);
  EXPECT_GE(corrected, 2);
  EXPECT_GE(taken_after_corrected, 1);
}

TEST(EvaluationAhead, AStateSavedBeforeTheStepTakesItContinuesBitwiseInAFreshBody) {
  // The save falls between the guard's evaluation ahead and the step that takes it: the body saves
  // its rotations from before that evaluation, which a fresh body, evaluating the start itself,
  // reproduces. (Saved after the evaluation, the fresh body's extraction started one step later and
  // the runs differed in their last bits.)
  Swing original(true);
  for (int n = 0; n < 12; ++n) original.step();
  ASSERT_GE(original.model.taken(), 1);
  DeformableBody::Rotations rotations;
  original.body.save_rotations(rotations);
  original.integrator.restart(Restart::state_saved);
  const DynamicState saved = original.state;
  Swing fresh(true);
  fresh.body.restore_rotations(rotations);
  fresh.integrator.restart(Restart::state_restored);
  fresh.state = saved;
  const int taken_before = original.model.taken();
  for (int n = 0; n < 12; ++n) {
    original.step();
    fresh.step();
    ASSERT_TRUE(bitwise_equal(original.state.displacement_m, fresh.state.displacement_m)) << "step " << n;
    ASSERT_TRUE(bitwise_equal(original.state.velocity_m_per_s, fresh.state.velocity_m_per_s)) << "step " << n;
  }
  EXPECT_GT(original.model.taken(), taken_before);  // the save did not drop the evaluation ahead
}

TEST(EvaluationAhead, IsTakenOnlyAtTheSameDisplacementWithNothingChangedSince) {
  Swing swing(true);
  for (int n = 0; n < 5; ++n) swing.step();
  const Eigen::VectorXd u = swing.state.displacement_m;
  Eigen::VectorXd force_ahead, force;
  DeformableBody::Rotations before, after;
  const auto ahead_then = [&](auto&& between) {
    swing.body.save_rotations(before);
    EXPECT_TRUE(swing.body.evaluate_ahead(u, force_ahead));
    const bool taken = between();
    swing.body.save_rotations(after);
    return taken;
  };
  // Taken: the forces, tangent and potential are a plain evaluation's at u from the same rotations.
  EXPECT_TRUE(ahead_then([&] { return swing.body.take_evaluation_ahead(u); }));
  const Eigen::MatrixXd tangent_ahead = xfem_test::dense(swing.body.tangent());
  const double potential_ahead = swing.body.potential_energy_at_last_evaluate_j();
  swing.body.restore_rotations(before);
  swing.body.evaluate_with_potential(u, force, true);
  EXPECT_TRUE(bitwise_equal(force, force_ahead));
  EXPECT_EQ(xfem_test::dense(swing.body.tangent()), tangent_ahead);
  EXPECT_EQ(swing.body.potential_energy_at_last_evaluate_j(), potential_ahead);
  // Not taken, the rotations as before the evaluation ahead: at another displacement (one bit off)...
  Eigen::VectorXd other = u;
  other[other.size() - 1] = std::nextafter(other[other.size() - 1], 1.0);
  EXPECT_FALSE(ahead_then([&] { return swing.body.take_evaluation_ahead(other); }));
  EXPECT_EQ(after.tet_warm_starts.size(), before.tet_warm_starts.size());
  for (size_t t = 0; t < before.tet_warm_starts.size(); ++t) {
    ASSERT_EQ(after.tet_warm_starts[t].coeffs(), before.tet_warm_starts[t].coeffs()) << "tet " << t;
    ASSERT_EQ(after.tet_turns_before[t].coeffs(), before.tet_turns_before[t].coeffs()) << "tet " << t;
  }
  // ... after another evaluate, after the rotations were restored, after the spring was set.
  EXPECT_FALSE(ahead_then([&] {
    swing.body.evaluate(u, force, false);
    return swing.body.take_evaluation_ahead(u);
  }));
  EXPECT_FALSE(ahead_then([&] {
    swing.body.restore_rotations(before);
    return swing.body.take_evaluation_ahead(u);
  }));
  EXPECT_FALSE(ahead_then([&] {
    swing.spring.set(pull_on_the_tip(), swing.body.term_layout());
    return swing.body.take_evaluation_ahead(u);
  }));
  // With the spring set, none is made (the tool moves between steps); idle again, one is.
  EXPECT_FALSE(swing.body.evaluate_ahead(u, force_ahead));
  swing.spring.set(std::nullopt, swing.body.term_layout());
  EXPECT_FALSE(swing.body.take_evaluation_ahead(u));
  EXPECT_TRUE(swing.body.evaluate_ahead(u, force_ahead));
  swing.spring.set(std::nullopt, swing.body.term_layout());  // idle to idle: no change
  EXPECT_TRUE(swing.body.take_evaluation_ahead(u));
}

TEST(EvaluationAhead, IsNotMadeWhileAStrokeCutsStepAfterStep) {
  // A stroke cuts the swinging beam across at x = 5.5 cm over three steps (a third of the crossed
  // tets each): a step that cut would not take an evaluation made at the end of the step before, so
  // none is made while the body is being cut (the guard takes its energy pass); the step after the
  // stroke makes one again and the next takes it. The steps are bitwise those of a model that
  // declines every evaluation ahead. (Made at every step's end, the two evaluations ahead of the
  // stroke's steps were wasted: each cost a whole assembly.)
  Swing ahead(true), declines(false);
  const std::vector<TetCut> cuts =
      xfem_test::plane_cuts(beam(), xfem_test::Plane{Eigen::Vector3d(1, 0.1, 0.05).normalized(), 0.0553});
  ASSERT_GE(cuts.size(), 6U);
  const size_t third = cuts.size() / 3;
  for (int n = 0; n < 14; ++n) {
    const int stroke_step = n - 6;  // steps 6, 7 and 8 cut
    if (stroke_step >= 0 && stroke_step < 3) {
      const auto first = cuts.begin() + static_cast<long>(third) * stroke_step;
      const auto end = stroke_step == 2 ? cuts.end() : first + static_cast<long>(third);
      const std::vector<TetCut> part(first, end);
      for (Swing* swing : {&ahead, &declines}) {
        swing->body.enrich(part, swing->state);
        swing->integrator.restart(Restart::system_grown);
      }
    }
    const int made_before = ahead.model.made(), taken_before = ahead.model.taken();
    const StepReport report = ahead.step();
    declines.step();
    ASSERT_GT(report.guard_s, 0.0) << "step " << n << ": the swing turns the beam past the guard's angle";
    if (stroke_step >= 0 && stroke_step < 3) {
      EXPECT_EQ(ahead.model.made(), made_before) << "step " << n << ": made while the stroke cuts";
    }
    if (stroke_step == 3) {
      EXPECT_GT(ahead.model.made(), made_before) << "the step after the stroke";
    }
    if (stroke_step == 4) {
      EXPECT_GT(ahead.model.taken(), taken_before) << "the second step after the stroke";
    }
    ASSERT_TRUE(bitwise_equal(ahead.state.displacement_m, declines.state.displacement_m)) << "step " << n;
    ASSERT_TRUE(bitwise_equal(ahead.state.velocity_m_per_s, declines.state.velocity_m_per_s)) << "step " << n;
  }
  EXPECT_GT(ahead.model.taken(), 5);
}

}  // namespace
}  // namespace tissue

namespace tissue {
namespace {

// Linearized at the predicted end the guard's start potential is the last guard's end potential,
// kept by the body (one energy pass a guarded step instead of two): the steps are bitwise those of a
// model that keeps none, across the tool's spring being set, and a state saved and restored between
// two guarded steps continues bitwise in a fresh body (the restored step makes the same pass before
// its evaluation moves the warm starts).
TEST(KeptPotential, TheStepsAreBitwiseThoseOfAModelThatKeepsNone) {
  Swing keeps(true, true), keeps_none(false, true);
  int guarded = 0;
  for (int n = 0; n < 45; ++n) {
    if (n == 30) {
      for (Swing* swing : {&keeps, &keeps_none}) swing->spring.set(pull_on_the_tip(), swing->body.term_layout());
    }
    const StepReport report = keeps.step();
    keeps_none.step();
    guarded += report.guard_s > 0.0 ? 1 : 0;
    ASSERT_TRUE(bitwise_equal(keeps.state.displacement_m, keeps_none.state.displacement_m)) << "step " << n;
    ASSERT_TRUE(bitwise_equal(keeps.state.velocity_m_per_s, keeps_none.state.velocity_m_per_s)) << "step " << n;
  }
  std::printf("  %d guarded steps: %d energy passes keeping the end's, %d without\n", guarded,
              keeps.model.potential_passes(), keeps_none.model.potential_passes());
  EXPECT_GE(guarded, 10);
  // Without a kept one: the start's and the end's pass of each guarded step, and the start's pass of a
  // step after a guarded one made before its evaluation (whether or not it is guarded itself).
  EXPECT_GE(keeps_none.model.potential_passes(), 2 * guarded);
  EXPECT_LT(keeps.model.potential_passes(), guarded + 10);
  EXPECT_EQ(keeps.model.made(), 0);  // nothing evaluated ahead in this mode
}

TEST(KeptPotential, AStateRestoredBetweenGuardedStepsContinuesBitwiseInAFreshBody) {
  Swing original(true, true);
  int guarded_at_save = 0;
  for (int n = 0; n < 12; ++n) guarded_at_save = original.step().guard_s > 0.0 ? 1 : 0;
  ASSERT_EQ(guarded_at_save, 1);  // the save falls after a step whose guard made its end's pass
  DeformableBody::Rotations rotations;
  original.body.save_rotations(rotations);
  original.integrator.restart(Restart::state_saved);
  const Eigen::VectorXd internal_state = original.integrator.internal_state();
  const DynamicState saved = original.state;
  Swing fresh(true, true);
  fresh.body.restore_rotations(rotations);
  fresh.integrator.restore_internal_state(internal_state);
  fresh.integrator.restart(Restart::state_restored);
  fresh.state = saved;
  // What the restored step's pass before its evaluation finds is what the original keeps, bitwise.
  const double kept_j = original.body.kept_potential_energy_j(saved.displacement_m);
  ASSERT_TRUE(std::isfinite(kept_j));
  EXPECT_EQ(fresh.body.potential_energy_j(saved.displacement_m), kept_j);
  int scaled = 0;
  for (int n = 0; n < 20; ++n) {
    scaled += original.step().energy_guarded ? 1 : 0;
    fresh.step();
    ASSERT_TRUE(bitwise_equal(original.state.displacement_m, fresh.state.displacement_m)) << "step " << n;
    ASSERT_TRUE(bitwise_equal(original.state.velocity_m_per_s, fresh.state.velocity_m_per_s)) << "step " << n;
  }
  std::printf("  %d of the 20 steps after the restore scaled by the guard\n", scaled);
  EXPECT_GT(fresh.model.potential_passes(), 0);
}

TEST(KeptPotential, IsKeptOnlyAtTheSameDisplacementWithNothingChangedSince) {
  Swing swing(true, true);
  for (int n = 0; n < 5; ++n) swing.step();
  const Eigen::VectorXd u = swing.state.displacement_m;
  const double energy_j = swing.body.potential_energy_j(u);
  EXPECT_EQ(swing.body.kept_potential_energy_j(u), energy_j);
  EXPECT_EQ(swing.body.potential_energy_j(u), energy_j);  // the pass changes nothing it reads
  Eigen::VectorXd other = u;
  other[other.size() - 1] = std::nextafter(other[other.size() - 1], 1.0);
  EXPECT_TRUE(std::isnan(swing.body.kept_potential_energy_j(other)));
  swing.spring.set(pull_on_the_tip(), swing.body.term_layout());
  EXPECT_TRUE(std::isnan(swing.body.kept_potential_energy_j(u)));
  const double pulled_j = swing.body.potential_energy_j(u);
  EXPECT_EQ(swing.body.kept_potential_energy_j(u), pulled_j);
  EXPECT_NE(pulled_j, energy_j);
  Eigen::VectorXd force;
  swing.body.evaluate(u, force, false);
  EXPECT_TRUE(std::isnan(swing.body.kept_potential_energy_j(u)));
}

}  // namespace
}  // namespace tissue
