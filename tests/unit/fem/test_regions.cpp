// Per-region materials in the co-rotational model (issue 25): every tet takes its region's Lame
// parameters and density, and a region boundary changes none of the model's invariants: a rigid
// motion gives no force, the rest state none, and the tangent matches finite differences where it
// is exact (a rotated rest state).
#include "core/fem/corotational.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/system/assembly.hpp"
#include "support/two_regions.hpp"

#include <gtest/gtest.h>

#include <numeric>
#include <stdexcept>

namespace tissue {
namespace {

const Material SOFT{1.0e5, 0.4, 1000.0};
const Material STIFF{1.0e6, 0.45, 1100.0};  // a tumour in soft tissue: E 10x, a little denser

// 3 x 2 x 2 cubes of 5 mm; the cubes with x < 5 mm are "soft", the others "stiff".
TetMesh two_region_box() {
  return test::split_at_x(make_box_mesh(3, 2, 2, 0.005), 0.005, {"soft", std::nullopt}, {"stiff", std::nullopt});
}

Eigen::VectorXd flatten(const std::vector<Eigen::Vector3d>& points) {
  Eigen::VectorXd flat(3 * static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) flat.segment<3>(3 * static_cast<Eigen::Index>(i)) = points[i];
  return flat;
}

struct TwoRegionModel {
  TetMesh mesh = two_region_box();
  CorotationalElasticity model{mesh, std::vector<Material>{SOFT, STIFF}};
  DofMap dofs = make_dof_map(mesh.vertex_count(), {});
  BlockSparseMatrix tangent{stiffness_pattern(mesh, dofs)};
  std::vector<TetSlots> slots = make_tet_slots(mesh, dofs, tangent);

  Eigen::VectorXd force(const Eigen::VectorXd& x) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
    tangent.set_zero();
    model.evaluate(x, f, &tangent, &slots);
    return f;
  }
  Eigen::MatrixXd dense_tangent() const {
    const int n = mesh.vertex_count();
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) {
        const int slot = tangent.find_slot(a, b);
        if (slot >= 0) k.block<3, 3>(3 * a, 3 * b) = tangent.block(slot);
      }
    }
    return k;
  }
  // sum_e K_e with each tet's own region's Lame parameters, assembled densely by hand.
  Eigen::MatrixXd expected_rest_stiffness() const {
    const int n = mesh.vertex_count();
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(3 * n, 3 * n);
    for (int t = 0; t < mesh.tet_count(); ++t) {
      const LameParameters lame = lame_parameters(mesh.region_of(t) == 0 ? SOFT : STIFF);
      const Matrix12d k_e = linear_stiffness_matrix(precompute_tet(mesh.rest_corners(t)), lame);
      const Tet& tet = mesh.tets[static_cast<size_t>(t)];
      for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
          k.block<3, 3>(3 * tet[static_cast<size_t>(i)], 3 * tet[static_cast<size_t>(j)]) +=
              k_e.block<3, 3>(3 * i, 3 * j);
        }
      }
    }
    return k;
  }
};

TEST(Regions, EachTetTakesItsRegionsMaterial) {
  TwoRegionModel box;
  int soft = 0, stiff = 0;
  for (int t = 0; t < box.mesh.tet_count(); ++t) {
    EXPECT_EQ(box.model.rest(t).material, box.mesh.region_of(t));
    (box.mesh.region_of(t) == 0 ? soft : stiff)++;
  }
  EXPECT_EQ(soft, 20);  // one cube column of 4 cubes, 5 tets each
  EXPECT_EQ(stiff, 40);
  box.force(flatten(box.mesh.rest_positions_m));
  const Eigen::MatrixXd expected = box.expected_rest_stiffness();
  // The same sums in another order: a few ulps of the largest entry.
  EXPECT_LT((box.dense_tangent() - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
}

TEST(Regions, TheRestStateAndRigidMotionsGiveNoForceAcrossTheBoundary) {
  TwoRegionModel box;
  const Eigen::VectorXd rest = flatten(box.mesh.rest_positions_m);
  // The rotations at rest are the identity to round-off: forces of order 1e-14 N.
  EXPECT_LT(box.force(rest).cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(2.3, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  Eigen::VectorXd moved = rest;
  for (Eigen::Index v = 0; v < moved.size() / 3; ++v) {
    moved.segment<3>(3 * v) = rotation * rest.segment<3>(3 * v) + Eigen::Vector3d(0.02, -0.01, 0.005);
  }
  // The stiff region's forces for a 1% strain are ~ E * strain * area ~ 1e6 * 0.01 * 2.5e-5 = 0.25 N:
  // a rigid motion's must vanish to round-off, far below 1e-9 of that.
  EXPECT_LT(box.force(moved).norm(), 1e-10);
}

TEST(Regions, TheTangentMatchesFiniteDifferencesAcrossTheBoundary) {
  // As Corotational.TangentMatchesFiniteDifferencesAtARotatedRestState, over both regions.
  TwoRegionModel box;
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  Eigen::VectorXd x = flatten(box.mesh.rest_positions_m);
  for (Eigen::Index v = 0; v < x.size() / 3; ++v) x.segment<3>(3 * v) = rotation * x.segment<3>(3 * v);
  box.force(x);
  const Eigen::MatrixXd analytic = box.dense_tangent();
  Eigen::MatrixXd numeric(x.size(), x.size());
  const double step_m = 1e-7;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    Eigen::VectorXd plus = x, minus = x;
    plus(j) += step_m;
    minus(j) -= step_m;
    numeric.col(j) = (box.force(plus) - box.force(minus)) / (2.0 * step_m);
  }
  EXPECT_LT((numeric - analytic).norm(), 1e-6 * analytic.norm());
}

TEST(Regions, LumpedMassesSumEachRegionsDensityTimesVolume) {
  const TetMesh mesh = two_region_box();
  const std::vector<double> masses = lumped_vertex_masses(mesh, {SOFT, STIFF});
  const double total = std::accumulate(masses.begin(), masses.end(), 0.0);
  const double cube_m3 = 0.005 * 0.005 * 0.005;
  const double expected = 4 * cube_m3 * SOFT.density_kg_per_m3 + 8 * cube_m3 * STIFF.density_kg_per_m3;
  EXPECT_NEAR(total, expected, 1e-12 * expected);
}

TEST(Regions, OneMaterialForEveryRegionIsTheSingleMaterialModelBitwise) {
  TwoRegionModel box;
  CorotationalElasticity single(box.mesh, SOFT);
  CorotationalElasticity listed(box.mesh, std::vector<Material>{SOFT, SOFT});
  Eigen::VectorXd x = flatten(box.mesh.rest_positions_m);
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) += 1e-4 * std::sin(3.0 * static_cast<double>(i));
  Eigen::VectorXd f_single = Eigen::VectorXd::Zero(x.size()), f_listed = Eigen::VectorXd::Zero(x.size());
  single.evaluate(x, f_single, nullptr, nullptr);
  listed.evaluate(x, f_listed, nullptr, nullptr);
  EXPECT_EQ(f_single, f_listed);
}

TEST(Regions, AMaterialCountThatDoesNotMatchTheRegionsIsRefused) {
  const TetMesh mesh = two_region_box();
  EXPECT_THROW(CorotationalElasticity(mesh, std::vector<Material>{SOFT}), ParameterError);
  EXPECT_THROW(CorotationalElasticity(mesh, std::vector<Material>{SOFT, Material{-1.0, 0.3, 1000.0}}), ParameterError);
  // The lumped masses and mass damping take one value per region too.
  EXPECT_THROW(lumped_vertex_masses(mesh, {SOFT}), std::invalid_argument);
  EXPECT_THROW(lumped_vertex_sums(mesh, std::vector<double>{1.0}), std::invalid_argument);
}

}  // namespace
}  // namespace tissue
