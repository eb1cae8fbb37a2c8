// Tests of the rotation extraction: proper for every F, polar rotation when det F > 0.
#include "core/fem/rotation.hpp"

#include <gtest/gtest.h>

#include <random>

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
    EXPECT_LT((r - r_true).norm(), 1e-8) << "trial " << trial;
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
    EXPECT_LT((r - r_true).norm(), 1e-8) << "trial " << trial;
    EXPECT_LT((r - rotation_by_svd(f)).norm(), 1e-8);
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
  EXPECT_LT((extract_rotation(flat, warm) - r_true).norm(), 1e-8);  // unique for rank 2
}

TEST(Rotation, WarmStartConvergesToTheSameRotation) {
  std::mt19937 rng(5);
  Eigen::Quaterniond warm = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d increment = Eigen::AngleAxisd(0.05, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (int step = 0; step < 100; ++step) {
    f = increment * f * Eigen::Vector3d(1.001, 0.999, 1.0).asDiagonal();
    const Eigen::Matrix3d r = extract_rotation(f, warm);
    EXPECT_LT((r - rotation_by_svd(f)).norm(), 1e-8) << "step " << step;
  }
}

}  // namespace
}  // namespace tissue
