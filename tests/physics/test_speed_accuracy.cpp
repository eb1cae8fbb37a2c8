// The accuracy side of issue 12's speed-ups: 200 steps of the frog and of a 12.8k-tet bar (the size
// of Vega's simpleBridge, which is not in the repository) end where the reference settings end:
// rotations extracted to ~1e-12 rad (the rule before issue 12). Two solver settings:
// * strict (PCG eps 1e-9): the trajectory is well conditioned, so the comparison is sharp;
// * real-time (PCG eps 1e-3, at most 10 iterations, as in the side-by-side benchmark): the truncated
//   solve makes the 200-step trajectory sensitive: perturbing the rotations at the rounding level
//   alone (stopping after one more Newton step) moved the end by 0.4-0.8% of the largest
//   displacement (measured in issue 12), so that is the floor any change meets here. Since issue 23
//   numbers the rows for locality (the same system, permuted: CG's iterates differ by rounding
//   only) the undamped bar swinging 0.28 m ends 2.9% apart (frog 1.0%), and single against double
//   matrix entries (a rounding-level change of the products) 1.1% (frog 0.7%).
#include "core/fixed_region.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/tissue.hpp"
#include "support/under_sanitizer.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <string>

namespace tissue {
namespace {

struct Scene {
  const char* name;
  double step_size_s;
  int steps;
  double pcg_tolerance;
  int pcg_max_iterations;
  double relative_tolerance;  ///< on the largest displacement
  double single_precision_tolerance;  ///< the same, single against double matrix entries
};

TetMesh scene_mesh(const Scene& scene) {
  return read_mesh(std::string(TISSUE_MESH_DIR) + (std::string(scene.name).rfind("frog", 0) == 0 ? "/frog.veg" : "/bar_40x8x8.veg"));
}

Eigen::VectorXd displacement_after(const Scene& scene, const RotationSettings& rotation,
                                   MatrixPrecision precision = MatrixPrecision::double_precision) {
  TetMesh mesh = scene_mesh(scene);
  TissueSettings settings;
  settings.body.material = {1.0e5, 0.4, 1000.0};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
  settings.body.rotation = rotation;
  settings.solver.pcg = {scene.pcg_tolerance, scene.pcg_max_iterations, precision};
  settings.integrator.newton.trigger_angle_rad = std::numeric_limits<double>::infinity();  // the linearized step
  settings.integrator.newton.energy_guard_angle_rad = std::numeric_limits<double>::infinity();
  settings.step_size_s = scene.step_size_s;
  Tissue tissue(std::move(mesh), settings);
  for (int step = 0; step < scene.steps; ++step) tissue.step();
  return tissue.state().displacement_m;
}

class SpeedAccuracy : public ::testing::TestWithParam<Scene> {};

TEST_P(SpeedAccuracy, FastRotationsEndWhereTheReferenceEnds) {
  const Scene& scene = GetParam();
  if (test::UNDER_SANITIZER && scene.pcg_max_iterations > 10) {
    GTEST_SKIP() << "strict solves take minutes under a sanitizer; the release run checks them";
  }
  RotationSettings reference;
  reference.max_error_rad = 4e-18;  // stop after a Newton step below 1e-6 rad: error ~1e-12 rad
  const Eigen::VectorXd expected = displacement_after(scene, reference);
  const Eigen::VectorXd fast = displacement_after(scene, RotationSettings{});
  const double largest_m = expected.cwiseAbs().maxCoeff();
  const double difference_m = (fast - expected).cwiseAbs().maxCoeff();
  std::printf("%s: largest displacement %.4g m, difference after %d steps %.3g m (%.2g relative)\n", scene.name,
              largest_m, scene.steps, difference_m, difference_m / largest_m);
  ASSERT_GT(largest_m, 1e-3);  // it moved: the comparison means something
  EXPECT_LT(difference_m, scene.relative_tolerance * largest_m);
}

// Issue 23: the products stream A's entries in single precision (sums in double). Against double
// entries, same rotations: strict, the solutions of the two systems differ by about cond(A) times
// the entries' rounding (6e-8); real time, the same floor as above.
TEST_P(SpeedAccuracy, SinglePrecisionProductsEndWhereDoubleEnds) {
  const Scene& scene = GetParam();
  if (test::UNDER_SANITIZER && scene.pcg_max_iterations > 10) {
    GTEST_SKIP() << "strict solves take minutes under a sanitizer; the release run checks them";
  }
  const Eigen::VectorXd expected = displacement_after(scene, RotationSettings{}, MatrixPrecision::double_precision);
  const Eigen::VectorXd single = displacement_after(scene, RotationSettings{}, MatrixPrecision::single);
  const double largest_m = expected.cwiseAbs().maxCoeff();
  const double difference_m = (single - expected).cwiseAbs().maxCoeff();
  std::printf("%s: largest displacement %.4g m, single against double after %d steps %.3g m (%.2g relative)\n",
              scene.name, largest_m, scene.steps, difference_m, difference_m / largest_m);
  ASSERT_GT(largest_m, 1e-3);
  EXPECT_LT(difference_m, scene.single_precision_tolerance * largest_m);
}

// Strict: each step's rotations differ by <= 1e-6 rad, a relative force change of <= 1e-6 (measured
// end difference 2.5e-8 on the frog), so 1e-6 bounds it with margin; single against double entries
// 1.4e-6 (frog) and 2.1e-7 (bar), bounded by 1e-4 (cond(A) ~1e3 times 6e-8). Real-time: 5%, a few
// times the rounding floor above (issue 12: frog 0.55%, bar 0.26%; issue 23: frog 1.0%, bar 2.9%;
// single against double 0.7% and 1.1%).
INSTANTIATE_TEST_SUITE_P(Settings, SpeedAccuracy,
                         ::testing::Values(Scene{"frog_strict", 0.01, 200, 1e-9, 10000, 1e-6, 1e-4},
                                           Scene{"bar_strict", 0.04, 200, 1e-9, 10000, 1e-6, 1e-4},
                                           Scene{"frog_real_time", 0.01, 200, 1e-3, 10, 0.05, 0.05},
                                           Scene{"bar_real_time", 0.04, 200, 1e-3, 10, 0.05, 0.05}),
                         [](const auto& test) { return std::string(test.param.name); });

}  // namespace
}  // namespace tissue
