// BackgroundContactStiffness: the K_c a worker condenses from its copy of the matrix is the one the
// caller's thread condenses from the matrix as it was at start(), bitwise, however the body's matrix
// changes while the worker runs; a failed matrix, a cancel and a restored result behave as documented.
#include "core/contact/background_contact_stiffness.hpp"
#include "core/contact/contact_stiffness.hpp"

#include "contact/frog_scene.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace tissue {
namespace {

using namespace contact_test;

struct Frog {
  TetMesh mesh = frog_mesh();
  SurfaceMesh surface = extract_surface(mesh);
  DeformableBody body{mesh, frog_settings(mesh)};
  Eigen::VectorXd zero_diagonal;

  void evaluate_at(double scale_m) {
    Eigen::VectorXd force;
    Eigen::VectorXd u = Eigen::VectorXd::Zero(body.dof_count());
    for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = scale_m * std::sin(0.37 * static_cast<double>(i));
    body.evaluate(u, force, /*update_tangent=*/true);
  }
  ContactStiffnessRequest request(const SurfacePoint& point) const {
    Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(body.dof_count());
    const ShiftedSystem system{&body.tangent(), 1.0, &diagonal};
    return contact_stiffness_request(
        system, body.dofs(),
        contact_interpolation(body.dofs(), surface.triangles[static_cast<size_t>(point.triangle)], point.barycentric),
        std::nullopt, 1e6, 0.0);
  }
};

// start_condense (contact.stiffnessRefactorRefreshes): K_c at another point from the factor the last
// start() made, without a factorization: bitwise what a fresh factorization of that same matrix gives
// there, although the body's K changed since; without a factor, nothing.
TEST(BackgroundContactStiffness, CondensesAnotherPointFromTheFactorItHolds) {
  Frog frog;
  BackgroundContactStiffness fresh_object;
  fresh_object.start_condense(frog.request(back_points(frog.surface, rest_positions(frog.mesh))[0]));
  EXPECT_FALSE(fresh_object.take().has_value());  // no factor yet
  EXPECT_FALSE(fresh_object.factored());

  frog.evaluate_at(1e-3);
  const std::vector<SurfacePoint> points = back_points(frog.surface, rest_positions(frog.mesh));
  ASSERT_GE(points.size(), 2u);
  const ContactStiffnessRequest first = frog.request(points[0]), second = frog.request(points[1]);
  EffectiveContactStiffness here;
  here.load(static_contact_system(frog.body.tangent(), frog.zero_diagonal));
  const std::optional<Eigen::Matrix3d> expected = condense_loaded(here, second);
  ASSERT_TRUE(expected.has_value());

  BackgroundContactStiffness background;
  background.start(static_contact_system(frog.body.tangent(), frog.zero_diagonal), first);
  ASSERT_TRUE(background.take().has_value());
  EXPECT_TRUE(background.factored());
  frog.evaluate_at(3e-3);  // the body goes on: the factor is of the matrix as it was
  background.start_condense(second);
  const std::optional<Eigen::Matrix3d> landed = background.take();
  ASSERT_TRUE(landed.has_value());
  EXPECT_TRUE(*landed == *expected) << "max difference " << (*landed - *expected).cwiseAbs().maxCoeff();
}

TEST(BackgroundContactStiffness, GivesWhatTheCallerComputesFromTheMatrixAtStart) {
  Frog frog;
  frog.evaluate_at(1e-3);  // a deformed, rotated state: K is not the rest stiffness
  const SurfacePoint point = back_points(frog.surface, rest_positions(frog.mesh))[0];
  const ContactStiffnessRequest request = frog.request(point);

  EffectiveContactStiffness here;
  here.load(static_contact_system(frog.body.tangent(), frog.zero_diagonal));
  const std::optional<Eigen::Matrix3d> expected = condense_loaded(here, request);
  ASSERT_TRUE(expected.has_value());

  BackgroundContactStiffness background;
  EXPECT_EQ(background.state(), BackgroundContactStiffness::State::idle);
  background.start(static_contact_system(frog.body.tangent(), frog.zero_diagonal), request);
  EXPECT_EQ(background.state(), BackgroundContactStiffness::State::running);
  // The body goes on while the worker runs: its K changes (another deformation), which the worker's
  // copy does not see.
  frog.evaluate_at(3e-3);
  const std::optional<Eigen::Matrix3d> landed = background.take();
  EXPECT_EQ(background.state(), BackgroundContactStiffness::State::idle);
  ASSERT_TRUE(landed.has_value());
  EXPECT_TRUE(*landed == *expected) << "max difference " << (*landed - *expected).cwiseAbs().maxCoeff();

  // K as it is now gives another K_c: the copy mattered.
  EffectiveContactStiffness now;
  now.load(static_contact_system(frog.body.tangent(), frog.zero_diagonal));
  const std::optional<Eigen::Matrix3d> changed = condense_loaded(now, request);
  ASSERT_TRUE(changed.has_value());
  EXPECT_GT((*changed - *expected).norm(), 1e-6 * expected->norm());
}

TEST(BackgroundContactStiffness, FailsCancelsAndTakesARestoredResult) {
  Frog frog;
  frog.evaluate_at(0.0);
  const SurfacePoint point = back_points(frog.surface, rest_positions(frog.mesh))[0];
  const ContactStiffnessRequest request = frog.request(point);

  // -K is not positive definite: the worker's factorization fails, and the result says so.
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(frog.body.dof_count());
  BackgroundContactStiffness background;
  background.start(ShiftedSystem{&frog.body.tangent(), -1.0, &diagonal}, request);
  background.wait();
  EXPECT_EQ(background.state(), BackgroundContactStiffness::State::done);
  EXPECT_FALSE(background.result().has_value());
  EXPECT_FALSE(background.take().has_value());

  // A diagonal of the wrong size cannot be loaded: done at once, failed.
  Eigen::VectorXd short_diagonal = Eigen::VectorXd::Zero(3);
  background.start(ShiftedSystem{&frog.body.tangent(), 1.0, &short_diagonal}, request);
  EXPECT_EQ(background.state(), BackgroundContactStiffness::State::done);
  EXPECT_FALSE(background.take().has_value());

  // Cancelled while running: nothing to take.
  background.start(static_contact_system(frog.body.tangent(), frog.zero_diagonal), request);
  background.cancel();
  EXPECT_EQ(background.state(), BackgroundContactStiffness::State::idle);
  EXPECT_FALSE(background.take().has_value());

  // A result from a saved state is taken as the worker's would be; a new start drops it.
  const Eigen::Matrix3d saved = 1234.5 * Eigen::Matrix3d::Identity();
  background.set_done(saved);
  ASSERT_TRUE(background.result().has_value());
  EXPECT_TRUE(*background.take() == saved);
  background.set_done(saved);
  background.start(static_contact_system(frog.body.tangent(), frog.zero_diagonal), request);
  const std::optional<Eigen::Matrix3d> fresh = background.take();
  ASSERT_TRUE(fresh.has_value());
  EXPECT_FALSE(*fresh == saved);
}

}  // namespace
}  // namespace tissue
