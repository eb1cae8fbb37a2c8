// Tests of growing the system in place (dissertation 4.2.2 and the pre-allocation of 6.2): cutting
// the frog through the middle, a few tets per step as a blade would, keeps every u-u slot and the
// storage layout with the default reserve, and CHOLMOD and PCG both solve the grown system. With
// no reserve the storage is re-laid out and every slot map is looked up again: the result equals
// the in-place growth.
#include "core/contact/point_spring.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/fixed_region.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "fem/xfem_test_helpers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <iostream>
#include <memory>
#include <span>
#include <string>
#include <tuple>
#include <vector>

namespace tissue {
namespace {

using xfem_test::dense;
using xfem_test::Plane;

BodySettings frog_settings(const TetMesh& mesh) {
  BodySettings settings;
  settings.material = Material{1.0e5, 0.4, 1000.0};
  settings.damping = RayleighDamping{2.0, 0.0};
  settings.gravity_m_per_s2 = Eigen::Vector3d(0.0, 0.0, -9.81);
  // Pinned by the lowest 4 mm of the belly (as the contact tests hold it).
  settings.fixed_vertices =
      vertices_in_box(mesh, Eigen::Vector3d(-0.035, -0.024, -1.0), Eigen::Vector3d(0.035, 0.024, 0.008));
  return settings;
}

// (row, column) of every block of the u rows, sorted.
std::vector<std::pair<int, int>> u_blocks(const BlockSparseMatrix& matrix, int u_rows) {
  std::vector<std::pair<int, int>> blocks;
  for (int r = 0; r < u_rows; ++r) {
    for (int s = matrix.row_begin(r); s < matrix.row_begin(r) + matrix.row_size(r); ++s) {
      if (matrix.slot_column(s) < u_rows) blocks.emplace_back(r, matrix.slot_column(s));
    }
  }
  std::sort(blocks.begin(), blocks.end());
  return blocks;
}

TEST(XfemGrowth, FrogCutThroughTheMiddleGrowsAndBothSolversStep) {
  const TetMesh mesh = read_veg(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  DeformableBody body(mesh, frog_settings(mesh));
  const int u_rows = body.dofs().free_vertex_count();
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count())};
  const double h = 1e-3;
  BackwardEuler cholmod(std::make_unique<CholmodSolver>());
  for (int step = 0; step < 5; ++step) cholmod.step(body, state, h);  // sagging: a deformed, moving state

  const std::uint64_t layout_before = body.tangent().layout_revision();
  const auto blocks_before = u_blocks(body.tangent(), u_rows);
  int relayouts = 0;
  int batches = 0;

  // A plane through the middle (tilted, so that it passes near no vertex), cut 10 tets per step.
  const Plane plane{Eigen::Vector3d(1.0, 0.05, 0.02).normalized(), 0.0013};
  const std::vector<TetCut> cuts = xfem_test::plane_cuts(mesh, plane);
  ASSERT_GT(cuts.size(), 100u);
  for (size_t first = 0; first < cuts.size(); first += 10) {
    const EnrichmentResult result =
        body.enrich(std::span<const TetCut>(cuts).subspan(first, std::min<size_t>(10, cuts.size() - first)));
    // Rows start compact: a batch re-lays the storage out at most once, doubling the rows it grows.
    EXPECT_LE(body.tangent().layout_revision(), layout_before + static_cast<std::uint64_t>(relayouts) + 1);
    relayouts += result.matrix_relayout ? 1 : 0;
    ++batches;
    const Eigen::VectorXd u_before = state.displacement_m;
    const Eigen::VectorXd v_before = state.velocity_m_per_s;
    body.grow_state(state);
    // Existing unknowns continue unchanged; the new ones start at rest.
    EXPECT_EQ(state.displacement_m.head(u_before.size()), u_before);
    EXPECT_EQ(state.velocity_m_per_s.head(v_before.size()), v_before);
    EXPECT_EQ(state.displacement_m.tail(body.dof_count() - u_before.size()).norm(), 0.0);
    cholmod.step(body, state, h);
  }
  std::cout << "frog: " << u_rows << " u rows, " << cuts.size() << " cut tets, " << body.enriched_dof_count()
            << " enriched unknowns, block-row capacity " << body.tangent().block_row_capacity() << ", "
            << body.tangent().nonzero_blocks() << " of " << body.tangent().slot_capacity() << " slots used\n";
  std::cout << "frog: " << relayouts << " re-layouts in " << batches << " batches of cuts\n";
  // The doubled rows take later cuts in place: most batches need no re-layout.
  EXPECT_LT(2 * relayouts, batches);
  // K^uu keeps every block it had (its slots may have moved).
  const auto blocks_after = u_blocks(body.tangent(), u_rows);
  EXPECT_TRUE(std::includes(blocks_after.begin(), blocks_after.end(), blocks_before.begin(), blocks_before.end()));
  EXPECT_EQ(body.mesh().tet_count(), mesh.tet_count());

  // Both solvers on the grown system, from the same state: PCG at a strict tolerance must land on
  // CHOLMOD's answer. dv differs by at most ~cond(A) * 1e-10 relative; the bound 1e-6 leaves room
  // for cond(A) up to 1e4 (the diagonal mass dominates A = M + h^2 K at h = 1 ms).
  DeformableBody pcg_body = body;
  DynamicState pcg_state = state;
  BackwardEuler pcg(std::make_unique<PcgSolver>(PcgSolver::Settings{1e-10, 10000}));
  for (int step = 0; step < 10; ++step) {
    cholmod.step(body, state, h);
    const StepReport report = pcg.step(pcg_body, pcg_state, h);
    EXPECT_TRUE(report.solve.converged);
  }
  ASSERT_TRUE(state.displacement_m.allFinite());
  ASSERT_TRUE(state.velocity_m_per_s.allFinite());
  const double difference = (state.velocity_m_per_s - pcg_state.velocity_m_per_s).norm();
  std::cout << "CHOLMOD vs PCG velocity difference " << difference / state.velocity_m_per_s.norm() << " relative\n";
  EXPECT_LT(difference, 1e-6 * state.velocity_m_per_s.norm());
  // The crack opened: the enriched unknowns moved.
  EXPECT_GT(state.displacement_m.tail(3 * body.enriched_dof_count()).norm(), 0.0);
}

TEST(XfemGrowth, RelayoutRecomputesEverySlotMap) {
  // No reserve at all: insertions re-lay the storage out, so every slot held (uncut tets, cut tets,
  // point spring) must be looked up again; with spare rows but compact rows (the default) one
  // re-layout makes room for the batch and the uncut tets' slots follow its map. Both grown bodies
  // must then compute exactly what the same body grown in place computes.
  const TetMesh mesh = make_box_mesh(8, 2, 2, 0.01);
  BodySettings settings;
  settings.material = Material{1.0e5, 0.4, 1000.0};
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<size_t>(v)].x() < 1e-9) settings.fixed_vertices.push_back(v);
  }
  settings.reserve = MatrixReserve{0.5, 8};  // room in every row: grows in place
  DeformableBody roomy(mesh, settings);
  settings.reserve = MatrixReserve{0.0, 1};  // no spare rows either: several re-layouts, slots searched
  DeformableBody tight(mesh, settings);
  settings.reserve = MatrixReserve{0.5, 1};  // the default: one re-layout for the batch, slots mapped
  DeformableBody compact(mesh, settings);
  const Tet& tet = mesh.tets[37];
  const PointSpring spring{
      {tet[0], tet[1], tet[3]}, Eigen::Vector3d(0.2, 0.3, 0.5), Eigen::Vector3d(0.05, 0.01, 0.03), 50.0};
  PointSpringTerm roomy_spring;
  PointSpringTerm tight_spring;
  PointSpringTerm compact_spring;
  roomy.attach(roomy_spring);
  tight.attach(tight_spring);
  compact.attach(compact_spring);
  roomy_spring.set(spring, roomy.term_layout());
  tight_spring.set(spring, tight.term_layout());
  compact_spring.set(spring, compact.term_layout());

  const auto cuts = xfem_test::plane_cuts(mesh, Plane{Eigen::Vector3d(1, 0.1, 0.2).normalized(), 0.045});
  EXPECT_FALSE(roomy.enrich(cuts).matrix_relayout);
  const std::uint64_t tight_layout = tight.tangent().layout_revision();
  EXPECT_TRUE(tight.enrich(cuts).matrix_relayout);
  EXPECT_GT(tight.tangent().layout_revision(), tight_layout + 1);  // the searching path
  const std::uint64_t compact_layout = compact.tangent().layout_revision();
  EXPECT_TRUE(compact.enrich(cuts).matrix_relayout);
  EXPECT_EQ(compact.tangent().layout_revision(), compact_layout + 1);  // the mapping path

  Eigen::VectorXd q(roomy.dof_count());
  for (Eigen::Index k = 0; k < q.size(); ++k) q(k) = 1e-4 * std::sin(0.7 * static_cast<double>(k));
  Eigen::VectorXd f_roomy;
  Eigen::VectorXd f_tight;
  Eigen::VectorXd f_compact;
  roomy.evaluate(q, f_roomy, true);
  tight.evaluate(q, f_tight, true);
  compact.evaluate(q, f_compact, true);
  EXPECT_EQ(f_roomy, f_tight);
  EXPECT_EQ(f_roomy, f_compact);
  EXPECT_EQ(dense(roomy.tangent()), dense(tight.tangent()));
  EXPECT_EQ(dense(roomy.tangent()), dense(compact.tangent()));
}

}  // namespace
}  // namespace tissue
