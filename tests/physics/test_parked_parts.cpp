// A piece cut free that falls out of the operating field leaves the dynamics (issue 41, item 3: no
// slowdown as cuts pile up): its elements add no force and no block, and its rows, which keep only
// their mass and weight, fall on as one rigid body. What physics says of that:
// - the piece's momentum is kept at the park (each row takes the mass-weighted mean velocity) and
//   then follows backward Euler's free fall exactly, v_{n+1} = v_n + h g for every row (no damping:
//   a free particle's step is exact to round-off);
// - the body left behind does not notice: it is decoupled from the piece in the exact solve, so it
//   moves as in the run that keeps the piece (the same scene with the field made huge), to the
//   round-off of two factorizations of different systems;
// - the tangent keeps nothing of the piece but zero blocks between real vertices, so the step's
//   product and assembly shrink with the body that is left.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace tissue {
namespace {

constexpr double GRAVITY = 9.81;

// The free-fall beam (test_free_fall.cpp): 10 x 2 x 2 cm of 1 cm cubes held at x = 0, E 2 MPa, no
// damping, exact solves, 10 ms steps, cut across at 75% by a vertical scalpel at 5.5 cm/s.
TissueSettings beam_settings(const TetMesh& mesh, double field_margin_fraction) {
  TissueSettings settings;
  settings.body.material = Material{2.0e6, 0.3, 1000.0};
  settings.body.damping = RayleighDamping{0.0, 0.0};
  settings.body.gravity_m_per_s2 = Eigen::Vector3d(0.0, 0.0, -GRAVITY);
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 1e-6);
  settings.solver.kind = LinearSolverKind::cholmod;
  settings.step_size_s = 0.01;
  settings.interaction.blade_length_m = 0.1;
  settings.field_margin_fraction = field_margin_fraction;
  return settings;
}

// The stroke's poses, one a step after 0.2 s at rest: the end falls free while the blade is still
// crossing (the tets complete as it passes their vertices), then the tool is taken away.
std::vector<ToolPose> stroke_poses(double step_s) {
  std::vector<ToolPose> poses(20, ToolPose{});
  const int stroke_steps = static_cast<int>(std::ceil(0.04 / (0.055 * step_s)));
  for (int n = 0; n <= stroke_steps; ++n) {
    const double y = -0.01 + 0.04 * n / stroke_steps;
    poses.push_back(ToolPose{Eigen::Vector3d(0.075, y, -0.05), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
  }
  poses.push_back(ToolPose{Eigen::Vector3d(0.075, 0.2, -0.05), Eigen::Quaterniond::Identity(), ToolMode::none});
  return poses;
}

// Displacements of the real vertices whose rest x is below `x_m` (the held part). [m]
Eigen::VectorXd held_part(const Tissue& tissue, double x_m) {
  const TetMesh& mesh = tissue.body().mesh();
  std::vector<double> values;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const int row = tissue.body().dofs().vertex_row[static_cast<size_t>(v)];
    if (row < 0 || mesh.rest_positions_m[static_cast<size_t>(v)].x() > x_m) continue;
    for (int k = 0; k < 3; ++k) values.push_back(tissue.state().displacement_m(3 * row + k));
  }
  return Eigen::Map<Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

TEST(PartsOutOfTheField, AFallenPieceLeavesTheDynamicsAndFallsOnAsOneBody) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  Tissue parking(mesh, beam_settings(mesh, 0.5));
  Tissue keeping(mesh, beam_settings(mesh, 1e6));
  // The field reaches 5 cm below the beam: the freed 2 cm end leaves it some 0.15 s into its fall.
  const std::vector<ToolPose> poses = stroke_poses(parking.settings().step_size_s);
  int steps = 0;
  int blocks_before = 0;
  while (parking.body().parked_row_count() == 0 && steps < 200) {
    blocks_before = parking.body().tangent().nonzero_blocks();
    if (static_cast<size_t>(steps) < poses.size()) {
      parking.set_tool(poses[static_cast<size_t>(steps)]);
      keeping.set_tool(poses[static_cast<size_t>(steps)]);
    }
    parking.step();
    keeping.step();
    ++steps;
  }
  const DeformableBody& body = parking.body();
  std::printf("parked after %d steps\n", steps);
  ASSERT_GT(body.parked_row_count(), 0) << "the piece never left the field";
  std::printf("parked %d rows after %d steps; tangent blocks %d -> %d (the piece's %d go)\n", body.parked_row_count(),
              steps, blocks_before, body.tangent().nonzero_blocks(), blocks_before - body.tangent().nonzero_blocks());

  // Every parked row moves with one velocity; every block of a parked row is zero or gone.
  const int rows = body.dof_count() / 3;
  std::vector<int> parked;
  for (int row = 0; row < rows; ++row) {
    if (body.parked(row)) parked.push_back(row);
  }
  const BlockSparseMatrix& tangent = body.tangent();
  const auto velocity = [&](int row) { return Eigen::Vector3d(parking.state().velocity_m_per_s.segment<3>(3 * row)); };
  for (int n = 0; n < 20; ++n) {
    const Eigen::Vector3d common = velocity(parked.front());
    for (const int row : parked) {
      EXPECT_LT((velocity(row) - common).norm(), 1e-12 * common.norm()) << "row " << row << " step " << n;
    }
    parking.step();
    keeping.step();
    // Backward Euler's free particle: v_{n+1} = v_n + h g, exactly but for the sum's round-off.
    const Eigen::Vector3d expected = common + parking.settings().step_size_s * Eigen::Vector3d(0.0, 0.0, -GRAVITY);
    EXPECT_LT((velocity(parked.front()) - expected).norm(), 1e-12 * expected.norm());
    // The step's tangent holds nothing of the piece.
    for (const int row : parked) {
      for (int s = tangent.row_begin(row); s < tangent.row_begin(row) + tangent.row_size(row); ++s) {
        if (tangent.slot_column(s) >= 0) {
          EXPECT_EQ(tangent.block(s).norm(), 0.0) << "row " << row;
        }
      }
    }
  }
  EXPECT_LT(tangent.nonzero_blocks(), blocks_before);

  // The piece's faces left the surface BVH's tree: out of it are exactly the triangles whose
  // corners all lie outside the operating field (the mesh's surface of the piece, its cut faces).
  const SurfaceBvh& bvh = parking.surface_bvh();
  const Eigen::AlignedBox3d field = parking.operating_field();
  const Eigen::VectorXd& x = parking.current_positions_m();
  int out = 0;
  for (int id = 0; id < bvh.triangle_count(); ++id) {
    const std::array<int, 3>& t = bvh.triangle(id);
    const bool outside = std::none_of(t.begin(), t.end(), [&](int v) { return field.contains(x.segment<3>(3 * v)); });
    EXPECT_EQ(bvh.in_tree(id), !outside) << "triangle " << id;
    out += bvh.in_tree(id) ? 0 : 1;
  }
  EXPECT_GT(out, 0);
  EXPECT_EQ(keeping.surface_bvh().triangle_count(), bvh.triangle_count());

  // The body left behind moves as if the piece were still there.
  const Eigen::VectorXd left = held_part(parking, 0.07);
  const Eigen::VectorXd reference = held_part(keeping, 0.07);
  const double difference = (left - reference).norm() / reference.norm();
  std::printf("held part after %d steps beside the run that keeps the piece: relative difference %.3g\n", steps + 20,
              difference);
  EXPECT_LT(difference, 1e-9);
}

// The same under the real-time solver (the Tissue FMU's default: CG with the two-level
// preconditioner, relative tolerance 1e-3, at most 10 iterations; and Jacobi CG capped alike): the
// parked rows are solved exactly in every step, so the piece keeps falling as one body. Before, CG
// left them off by the cap's error, and nothing pulled them back together: the hatched frog's parked
// pieces swelled as they fell (x 1.06 through tissue-host: 9.7 -> 36.7 cm^3 in 1.3 s).
class ParkedUnderTheRealTimeSolver : public ::testing::TestWithParam<LinearSolverKind> {};
TEST_P(ParkedUnderTheRealTimeSolver, APieceFallsOnAsOneBody) {
  const TetMesh mesh = make_box_mesh(10, 2, 2, 0.01);
  TissueSettings settings = beam_settings(mesh, 0.5);
  settings.solver.kind = GetParam();
  settings.solver.pcg = PcgSolver::Settings{1e-3, 10};
  Tissue tissue(mesh, settings);
  const std::vector<ToolPose> poses = stroke_poses(settings.step_size_s);
  // Under Jacobi CG capped at 10 iterations the freed piece sinks slowly (issue 40): it leaves the
  // field after ~200 steps, the count moving by a few percent with the products' rounding.
  int steps = 0;
  for (; tissue.body().parked_row_count() == 0 && steps < 400; ++steps) {
    if (static_cast<size_t>(steps) < poses.size()) tissue.set_tool(poses[static_cast<size_t>(steps)]);
    tissue.step();
  }
  const DeformableBody& body = tissue.body();
  std::printf("parked after %d steps\n", steps);
  ASSERT_GT(body.parked_row_count(), 0) << "the piece never left the field";
  std::vector<int> parked;
  for (int row = 0; row < body.dof_count() / 3; ++row) {
    if (body.parked(row)) parked.push_back(row);
  }
  const auto velocity = [&](int row) { return Eigen::Vector3d(tissue.state().velocity_m_per_s.segment<3>(3 * row)); };
  const auto points = [&] { return *body.block_positions(tissue.state().displacement_m); };
  const std::vector<Eigen::Vector3d> parked_at = points();
  for (int n = 0; n < 50; ++n) {
    const Eigen::Vector3d common = velocity(parked.front());
    tissue.step();
    // Backward Euler's free particle (no damping here): v_{n+1} = v_n + h g, to the sum's round-off.
    const Eigen::Vector3d expected = common + settings.step_size_s * Eigen::Vector3d(0.0, 0.0, -GRAVITY);
    for (const int row : parked) {
      EXPECT_LT((velocity(row) - expected).norm(), 1e-12 * expected.norm()) << "row " << row << " step " << n;
    }
  }
  // Its shape: every point moved by the same displacement.
  const std::vector<Eigen::Vector3d> now = points();
  const Eigen::Vector3d moved =
      now[static_cast<size_t>(parked.front())] - parked_at[static_cast<size_t>(parked.front())];
  EXPECT_GT(moved.norm(), 0.1);
  for (const int row : parked) {
    const auto r = static_cast<size_t>(row);
    EXPECT_LT((now[r] - parked_at[r] - moved).norm(), 1e-9) << "row " << row;
  }
}
INSTANTIATE_TEST_SUITE_P(CappedSolvers, ParkedUnderTheRealTimeSolver,
                         ::testing::Values(LinearSolverKind::pcg_two_level, LinearSolverKind::pcg));

}  // namespace
}  // namespace tissue
