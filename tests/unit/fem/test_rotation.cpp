// Tests of the rotation extraction: proper for every F, polar rotation when det F > 0.
#include "core/fem/rotation.hpp"

#include "core/parameter_error.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace tissue {
namespace {

void expect_proper_rotation(const Eigen::Matrix3d& r) {
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

TEST(Rotation, MatchesPolarDecompositionForPositiveDeterminant) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> stretch(0.3, 2.5);
  for (int trial = 0; trial < 500; ++trial) {
    const Eigen::Matrix3d r_true = random_rotation(rng);
    const Eigen::Matrix3d u = random_rotation(rng);
    const Eigen::Matrix3d s =
        u * Eigen::Vector3d(stretch(rng), stretch(rng), stretch(rng)).asDiagonal() * u.transpose();
    const Eigen::Matrix3d f = r_true * s;  // polar decomposition by construction
    Eigen::Quaterniond cold = Eigen::Quaterniond::Identity();
    const Eigen::Matrix3d r = extract_rotation(f, cold);
    expect_proper_rotation(r);
    // The default accepts an error up to max_error_rad (1e-6 rad); |R - R_true|_F = sqrt(8) sin(e/2).
    EXPECT_LT((r - r_true).norm(), 1.5 * RotationSettings{}.max_error_rad) << "trial " << trial;
    RotationSettings strict;
    strict.max_error_rad = 4e-18;  // the pre-issue-12 rule: stop after a Newton step below 1e-6 rad
    Eigen::Quaterniond cold_again = Eigen::Quaterniond::Identity();
    EXPECT_LT((extract_rotation(f, cold_again, strict) - r_true).norm(), 1e-10) << "trial " << trial;
  }
}

TEST(Rotation, HalfTurnFromIdentityIsNotMistakenForASaddle) {
  // F = a rotation by pi about x: from the identity start the fast iteration sees zero torque
  // (R^T F symmetric), a saddle of tr(R^T F). The second-order check must catch it.
  const Eigen::Matrix3d f = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Quaterniond warm = Eigen::Quaterniond::Identity();
  EXPECT_LT((extract_rotation(f, warm) - f).norm(), 1e-10);
}

TEST(Rotation, InvertedDeformationGivesProperRotationThatFlipsTheSmallestAxis) {
  std::mt19937 rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Matrix3d r_true = random_rotation(rng);
    const Eigen::Matrix3d u = random_rotation(rng);
    // Compressed through itself along one axis: stretches (1.2, 0.9, -0.3).
    const Eigen::Matrix3d f = r_true * u * Eigen::Vector3d(1.2, 0.9, -0.3).asDiagonal() * u.transpose();
    ASSERT_LT(f.determinant(), 0.0);
    Eigen::Quaterniond warm = Eigen::Quaterniond::Identity();
    const Eigen::Matrix3d r = extract_rotation(f, warm);
    expect_proper_rotation(r);
    // Invertible FEM: R^T F = U diag(1.2, 0.9, -0.3) U^T, i.e. R = r_true.
    EXPECT_LT((r - r_true).norm(), 1.5e-6) << "trial " << trial;
    EXPECT_LT((r - rotation_by_svd(f)).norm(), 1.5e-6);
  }
}

TEST(Rotation, FlatAndCollapsedTetsStillGiveProperRotations) {
  std::mt19937 rng(3);
  const Eigen::Matrix3d r_true = random_rotation(rng);
  const Eigen::Matrix3d flat = r_true * Eigen::Vector3d(1.5, 0.7, 0.0).asDiagonal();  // rank 2
  const Eigen::Matrix3d line = r_true * Eigen::Vector3d(1.0, 0.0, 0.0).asDiagonal();  // rank 1
  const Eigen::Matrix3d point = Eigen::Matrix3d::Zero();
  for (const Eigen::Matrix3d& f : {flat, line, point}) {
    Eigen::Quaterniond warm = Eigen::Quaterniond::Identity();
    expect_proper_rotation(extract_rotation(f, warm));
    expect_proper_rotation(rotation_by_svd(f));
  }
  Eigen::Quaterniond warm = Eigen::Quaterniond::Identity();
  EXPECT_LT((extract_rotation(flat, warm) - r_true).norm(), 1.5e-6);  // unique for rank 2
}

TEST(Rotation, WarmStartConvergesToTheSameRotation) {
  std::mt19937 rng(5);
  Eigen::Quaterniond warm = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d increment = Eigen::AngleAxisd(0.05, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (int step = 0; step < 100; ++step) {
    f = increment * f * Eigen::Vector3d(1.001, 0.999, 1.0).asDiagonal();
    const Eigen::Matrix3d r = extract_rotation(f, warm);
    EXPECT_LT((r - rotation_by_svd(f)).norm(), 1.5e-6) << "step " << step;
  }
}

// A turn about a fixed axis, seen between any two fixed frames (q_k = A exp(k theta) B), is
// extrapolated exactly: q_k (q_{k-1}^-1 q_k) = A exp((k+1) theta) B. A quaternion and its negative
// are the same rotation: either sign of the turn before gives the same next rotation.
TEST(Rotation, ExtrapolatedTurnOfASteadyTurnIsItsNextTurn) {
  std::mt19937 rng(23);
  std::normal_distribution<double> normal;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Quaterniond a(random_rotation(rng)), b(random_rotation(rng));
    const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    const double theta_rad = 0.4 * normal(rng);
    const auto turn = [&](int k) { return a * Eigen::Quaterniond(Eigen::AngleAxisd(k * theta_rad, axis)) * b; };
    const int k = trial % 7;
    const Eigen::Matrix3d next = turn(k + 1).toRotationMatrix();
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Quaterniond before(sign * turn(k - 1).coeffs());
      const Eigen::Quaterniond guess = extrapolated_turn(turn(k), before);
      EXPECT_NEAR(guess.norm(), 1.0, 1e-15);
      EXPECT_LT((guess.toRotationMatrix() - next).norm(), 1e-13) << "trial " << trial << " sign " << sign;
    }
  }
  // Not turning: the rotation itself.
  const Eigen::Quaterniond still(random_rotation(rng));
  EXPECT_LT((extrapolated_turn(still, still).coeffs() - still.coeffs()).norm(), 1e-15);
}

// F = R_true U with U symmetric positive definite, principal stretches in [0.2, 2].
Eigen::Matrix3d random_deformation(std::mt19937& rng, Eigen::Matrix3d* rotation = nullptr) {
  std::uniform_real_distribution<double> stretch(0.2, 2.0);
  const Eigen::Matrix3d r_true = random_rotation(rng);
  const Eigen::Matrix3d axes = random_rotation(rng);
  if (rotation != nullptr) *rotation = r_true;
  return r_true * axes * Eigen::Vector3d(stretch(rng), stretch(rng), stretch(rng)).asDiagonal() * axes.transpose();
}

TEST(Rotation, OneNewtonStepLeavesAnErrorCubicInTheWarmStartsError) {
  // The stopping rule's premise (rotation.hpp): from a warm start off by delta, one Newton step
  // leaves at most ~0.55 delta^3; asserted with 0.7 (the rule itself assumes 4).
  std::mt19937 rng(17);
  std::normal_distribution<double> normal;
  RotationSettings one_step;
  one_step.max_iterations = 1;
  one_step.max_error_rad = 1e300;  // accept the first Newton step
  for (const double delta : {1e-3, 3e-3, 1e-2, 3e-2}) {
    for (int trial = 0; trial < 300; ++trial) {
      Eigen::Matrix3d r_true;
      const Eigen::Matrix3d f = random_deformation(rng, &r_true);
      const Eigen::Vector3d axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
      Eigen::Quaterniond warm = Eigen::Quaterniond(r_true) * Eigen::Quaterniond(Eigen::AngleAxisd(delta, axis));
      const Eigen::Matrix3d r = extract_rotation(f, warm, one_step);
      const double error_rad = Eigen::AngleAxisd(r.transpose() * r_true).angle();
      EXPECT_LE(error_rad, 0.7 * delta * delta * delta) << "delta " << delta << " trial " << trial;
    }
  }
}

TEST(Rotation, BatchedExtractionEqualsOneAtATime) {
  std::mt19937 rng(23);
  std::normal_distribution<double> normal;
  std::vector<Eigen::Matrix3d> gradients;
  for (int k = 0; k < 40; ++k) gradients.push_back(random_deformation(rng));
  gradients.push_back(Eigen::Matrix3d::Zero());                                      // nothing to extract
  gradients.push_back(Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN()));  // not finite
  gradients.push_back(Eigen::Vector3d(1.2, 0.9, -0.3).asDiagonal());                 // inverted
  gradients.push_back(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix());  // saddle
  gradients.push_back(Eigen::Vector3d(1.0, 0.0, 0.0).asDiagonal());                  // a line
  // With turns before, each lane starts from extrapolated_turn (and, kept, its warm start as it was
  // becomes the turn before).
  for (const bool extrapolated : {false, true})
    for (const double max_error_rad : {RotationSettings{}.max_error_rad, 4e-18}) {
      RotationSettings settings;
      settings.max_error_rad = max_error_rad;
      for (int count = 1; count <= ROTATION_BATCH; ++count) {
        for (size_t first = 0; first + static_cast<size_t>(count) <= gradients.size();
             first += static_cast<size_t>(count)) {
          std::array<Eigen::Quaterniond, ROTATION_BATCH> warm_batch{};
          std::array<Eigen::Matrix3d, ROTATION_BATCH> rotation_batch{};
          std::array<Eigen::Quaterniond*, ROTATION_BATCH> warm_pointers{};
          std::array<Eigen::Matrix3d*, ROTATION_BATCH> rotation_pointers{};
          std::array<Eigen::Quaterniond, ROTATION_BATCH> before_batch{};
          std::array<Eigen::Quaterniond*, ROTATION_BATCH> before_pointers{};
          for (size_t l = 0; l < static_cast<size_t>(count); ++l) {
            warm_batch[l] = Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * normal(rng), Eigen::Vector3d::UnitZ()));
            before_batch[l] = Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * normal(rng), Eigen::Vector3d::UnitY()));
            warm_pointers[l] = &warm_batch[l];
            rotation_pointers[l] = &rotation_batch[l];
            before_pointers[l] = &before_batch[l];
          }
          const std::array<Eigen::Quaterniond, ROTATION_BATCH> warm_single = warm_batch;
          const std::array<Eigen::Quaterniond, ROTATION_BATCH> before_single = before_batch;
          extract_rotations(count, &gradients[first], warm_pointers.data(), rotation_pointers.data(), settings,
                            extrapolated ? TurnsBefore{before_pointers.data(), true} : TurnsBefore{});
          for (size_t l = 0; l < static_cast<size_t>(count); ++l) {
            Eigen::Quaterniond warm =
                extrapolated ? extrapolated_turn(warm_single[l], before_single[l]) : warm_single[l];
            EXPECT_EQ(before_batch[l].coeffs(), (extrapolated ? warm_single[l] : before_single[l]).coeffs());
            const Eigen::Matrix3d single = extract_rotation(gradients[first + l], warm, settings);
            EXPECT_LT((rotation_batch[l] - single).norm(), 1e-13)
                << "gradient " << first + l << " of a batch of " << count;
            EXPECT_LT((warm_batch[l].coeffs() - warm.coeffs()).norm(), 1e-13) << "gradient " << first + l;
          }
        }
      }
    }
}

TEST(Rotation, SettingsOutsideTheirRangeAreRefused) {
  RotationSettings settings;
  EXPECT_NO_THROW(validate(settings));
  settings.max_error_rad = 0.0;
  EXPECT_THROW(validate(settings), ParameterError);
  settings.max_error_rad = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(validate(settings), ParameterError);
  settings = RotationSettings{};
  settings.max_iterations = 0;
  EXPECT_THROW(validate(settings), ParameterError);
}

}  // namespace
}  // namespace tissue
