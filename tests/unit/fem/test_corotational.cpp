// Tests of the co-rotational model (eq. 3.13): rigid motions give no force, forces and tangent
// agree with the textbook R K_e (R^T x - X) and R K_e R^T, the tangent matches finite differences
// where it is exact, and lumped masses add up to rho V.
#include "core/fem/corotational.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/system/assembly.hpp"
#include "core/system/rayleigh_damping.hpp"

#include <gtest/gtest.h>

#include <numeric>
#include <random>

namespace tissue {
namespace {

const Material MATERIAL{1.0e5, 0.4, 1000.0};

TetMesh one_tet() {
  TetMesh mesh;
  mesh.rest_positions_m = {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.011, 0.001, -0.002),
                           Eigen::Vector3d(0.002, 0.009, 0.001), Eigen::Vector3d(-0.001, 0.002, 0.012)};
  mesh.tets = {Tet{0, 1, 2, 3}};
  return mesh;
}

Eigen::VectorXd flatten(const std::vector<Eigen::Vector3d>& points) {
  Eigen::VectorXd flat(3 * static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) flat.segment<3>(3 * static_cast<Eigen::Index>(i)) = points[i];
  return flat;
}

Eigen::VectorXd rigidly_moved(const TetMesh& mesh, const Eigen::Matrix3d& rotation, const Eigen::Vector3d& shift) {
  Eigen::VectorXd x = flatten(mesh.rest_positions_m);
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) x.segment<3>(3 * v) = rotation * x.segment<3>(3 * v) + shift;
  return x;
}

// The whole model on one tet with nothing fixed: forces and the assembled tangent as dense arrays.
struct OneTetModel {
  TetMesh mesh = one_tet();
  CorotationalElasticity model{mesh, MATERIAL};
  DofMap dofs = make_dof_map(4, {});
  BlockSparseMatrix tangent{stiffness_pattern(mesh, dofs)};
  std::vector<TetSlots> slots = make_tet_slots(mesh, dofs, tangent);

  Eigen::VectorXd force(const Eigen::VectorXd& x) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(12);
    tangent.set_zero();
    model.evaluate(x, f, &tangent, &slots);
    return f;
  }
  Matrix12d dense_tangent() const {
    Matrix12d k;
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) k.block<3, 3>(3 * a, 3 * b) = tangent.block(tangent.find_slot(a, b));
    }
    return k;
  }
};

TEST(Corotational, RigidRotationGivesZeroForceButLinearFemDoesNot) {
  OneTetModel tet;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::VectorXd x = rigidly_moved(tet.mesh, rotation, Eigen::Vector3d(0.3, -0.1, 0.2));
  const Eigen::VectorXd f = tet.force(x);
  // Force scale of a 1% strain: E * 0.01 * (edge ~1 cm)^2 = 1e-4 N. Round-off is ~1e-16 of the
  // stress times the area, so 1e-12 N is a generous bound for "zero".
  EXPECT_LT(f.norm(), 1e-12);
  const Matrix12d k_linear = linear_stiffness_matrix(tet.model.rest(0), tet.model.lame()[0]);
  const Eigen::VectorXd linear_force = k_linear * (x - flatten(tet.mesh.rest_positions_m));
  EXPECT_GT(linear_force.norm(), 1e-2);  // the ghost force of linear FEM under a 0.9 rad turn
}

TEST(Corotational, ForceAndTangentEqualTheTextbookFormulas) {
  OneTetModel tet;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> jitter(-0.002, 0.002);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.6, Eigen::Vector3d(0.2, 1, 0.3).normalized()).toRotationMatrix();
  Eigen::VectorXd x = rigidly_moved(tet.mesh, rotation, Eigen::Vector3d::Zero());
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += jitter(rng);
  const Eigen::VectorXd f = tet.force(x);

  const Eigen::Matrix3d r = tet.model.rotation(0);
  Matrix12d block_rotation = Matrix12d::Zero();
  for (int i = 0; i < 4; ++i) block_rotation.block<3, 3>(3 * i, 3 * i) = r;
  const Matrix12d k_e = linear_stiffness_matrix(tet.model.rest(0), tet.model.lame()[0]);
  const Eigen::VectorXd expected =
      block_rotation * k_e * (block_rotation.transpose() * x - flatten(tet.mesh.rest_positions_m));
  EXPECT_LT((f - expected).norm(), 1e-12 * expected.norm());
  const Matrix12d expected_tangent = block_rotation * k_e * block_rotation.transpose();
  EXPECT_LT((tet.dense_tangent() - expected_tangent).norm(), 1e-12 * expected_tangent.norm());
}

TEST(Corotational, TangentMatchesFiniteDifferencesAtARotatedRestState) {
  // At x = R X the rotated strain is zero, so the dR/dx term that R K R^T leaves out vanishes:
  // the tangent is exact there. Central differences with step 1e-7 m have truncation error
  // O(step^2 * f''') and round-off O(1e-16 |f| / step); 1e-6 relative covers both.
  OneTetModel tet;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::VectorXd x = rigidly_moved(tet.mesh, rotation, Eigen::Vector3d(0.01, 0.0, 0.0));
  tet.force(x);
  const Matrix12d analytic = tet.dense_tangent();
  Matrix12d numeric;
  const double step_m = 1e-7;
  for (int j = 0; j < 12; ++j) {
    Eigen::VectorXd plus = x, minus = x;
    plus(j) += step_m;
    minus(j) -= step_m;
    numeric.col(j) = (tet.force(plus) - tet.force(minus)) / (2.0 * step_m);
  }
  EXPECT_LT((numeric - analytic).norm(), 1e-6 * analytic.norm());
}

TEST(Corotational, ElasticEnergyIsHalfTheRotatedQuadraticForm) {
  OneTetModel tet;
  Eigen::VectorXd x = flatten(tet.mesh.rest_positions_m);
  x(3) += 0.0005;
  x(7) -= 0.0003;
  tet.force(x);
  const Matrix12d k_e = linear_stiffness_matrix(tet.model.rest(0), tet.model.lame()[0]);
  Matrix12d block_rotation = Matrix12d::Zero();
  for (int i = 0; i < 4; ++i) block_rotation.block<3, 3>(3 * i, 3 * i) = tet.model.rotation(0);
  const Eigen::VectorXd u = block_rotation.transpose() * x - flatten(tet.mesh.rest_positions_m);
  const double expected = 0.5 * u.dot(k_e * u);
  EXPECT_NEAR(tet.model.elastic_energy_j(x), expected, 1e-12 * expected);
}

TEST(Corotational, LumpedMassesSumToDensityTimesVolume) {
  const TetMesh mesh = make_box_mesh(6, 3, 2, 0.01);
  const std::vector<double> masses = lumped_vertex_masses(mesh, {Material{1.0e5, 0.4, 1000.0}});
  const double total = std::accumulate(masses.begin(), masses.end(), 0.0);
  const double volume_m3 = 6 * 3 * 2 * 1e-6;
  EXPECT_NEAR(total, 1000.0 * volume_m3, 1e-12 * total);
  for (double m : masses) EXPECT_GT(m, 0.0);
}

TEST(Material, RefusesOutOfRangeParameters) {
  EXPECT_THROW(validate(Material{0.0, 0.3, 1000.0}), ParameterError);
  EXPECT_THROW(validate(Material{-1.0, 0.3, 1000.0}), ParameterError);
  EXPECT_THROW(validate(Material{1e5, 0.5, 1000.0}), ParameterError);
  EXPECT_THROW(validate(Material{1e5, -0.1, 1000.0}), ParameterError);
  EXPECT_THROW(validate(Material{1e5, 0.3, 0.0}), ParameterError);
  EXPECT_THROW(validate(Material{std::nan(""), 0.3, 1000.0}), ParameterError);
  EXPECT_THROW(validate(RayleighDamping{-1.0, 0.0}), ParameterError);
  EXPECT_NO_THROW(validate(Material{1e5, 0.0, 1000.0}));
  EXPECT_NO_THROW(validate(Material{1e5, 0.499, 1000.0}));
}

}  // namespace
}  // namespace tissue
