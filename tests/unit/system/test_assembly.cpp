// Tests of the assembly maps: DOF numbering with fixed vertices, the stiffness pattern of a
// small tet chain, and the per-tet slot table (assembling through it equals a dense scatter).
#include "core/system/assembly.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>
#include <stdexcept>
#include <vector>

namespace tissue {
namespace {

// Three tets in a chain over six vertices: vertex 0 only in tet 0, vertex 5 only in tet 2,
// so vertices 1 and 5 share no tet.
TetMesh tet_chain() {
  TetMesh mesh;
  mesh.rest_positions_m = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {2, 2, 2}};
  mesh.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}, {2, 3, 4, 5}};
  return mesh;
}

TEST(Assembly, DofMapNumbersFreeVerticesInOrder) {
  const DofMap dofs = make_dof_map(6, {4, 0, 4});  // unsorted, with a duplicate
  EXPECT_EQ(dofs.vertex_row, (std::vector<int>{-1, 0, 1, 2, -1, 3}));
  EXPECT_EQ(dofs.row_vertex, (std::vector<int>{1, 2, 3, 5}));
  EXPECT_EQ(dofs.free_vertex_count(), 4);

  const DofMap all_free = make_dof_map(3, {});
  EXPECT_EQ(all_free.vertex_row, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(make_dof_map(2, {0, 1}).free_vertex_count(), 0);
  EXPECT_THROW(make_dof_map(3, {3}), std::out_of_range);
  EXPECT_THROW(make_dof_map(3, {-1}), std::out_of_range);
}

TEST(Assembly, StiffnessPatternCouplesVerticesSharingATet) {
  const TetMesh mesh = tet_chain();
  const DofMap dofs = make_dof_map(mesh.vertex_count(), {0});  // rows: v1..v5 -> 0..4
  const auto pattern = stiffness_pattern(mesh, dofs);
  ASSERT_EQ(pattern.size(), 5U);
  EXPECT_EQ(pattern[0], (std::vector<int>{0, 1, 2, 3}));     // v1: v2 v3 v4 (not v5; v0 fixed)
  EXPECT_EQ(pattern[1], (std::vector<int>{0, 1, 2, 3, 4}));  // v2: all
  EXPECT_EQ(pattern[2], (std::vector<int>{0, 1, 2, 3, 4}));  // v3: all
  EXPECT_EQ(pattern[3], (std::vector<int>{0, 1, 2, 3, 4}));  // v4: all
  EXPECT_EQ(pattern[4], (std::vector<int>{1, 2, 3, 4}));     // v5: v2 v3 v4

  // A free vertex in no tet still has its own (diagonal) row.
  TetMesh lonely = mesh;
  lonely.rest_positions_m.emplace_back(5, 5, 5);
  const auto lonely_pattern = stiffness_pattern(lonely, make_dof_map(lonely.vertex_count(), {0}));
  EXPECT_EQ(lonely_pattern.back(), (std::vector<int>{5}));
}

TEST(Assembly, TetSlotsPointAtTheBlocksOfEachVertexPair) {
  const TetMesh mesh = tet_chain();
  const DofMap dofs = make_dof_map(mesh.vertex_count(), {0});
  const BlockSparseMatrix matrix(stiffness_pattern(mesh, dofs));
  const auto slots = make_tet_slots(mesh, dofs, matrix);
  ASSERT_EQ(slots.size(), 3U);
  for (int t = 0; t < 3; ++t) {
    const Tet& tet = mesh.tets[static_cast<size_t>(t)];
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const int slot = slots[static_cast<size_t>(t)][static_cast<size_t>(4 * a + b)];
        const int row = dofs.vertex_row[static_cast<size_t>(tet[static_cast<size_t>(a)])];
        const int col = dofs.vertex_row[static_cast<size_t>(tet[static_cast<size_t>(b)])];
        if (row < 0 || col < 0) {
          EXPECT_EQ(slot, -1) << "tet " << t << " pair " << a << b;
        } else {
          EXPECT_GE(slot, 0);
          EXPECT_EQ(slot, matrix.find_slot(row, col));
          EXPECT_EQ(matrix.slot_column(slot), col);
        }
      }
    }
  }
  // Tet 0 holds the fixed vertex 0 at local index 0: its whole first row and column are -1.
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(slots[0][static_cast<size_t>(k)], -1);
    EXPECT_EQ(slots[0][static_cast<size_t>(4 * k)], -1);
  }
}

TEST(Assembly, AssemblingThroughSlotsEqualsDenseScatter) {
  const TetMesh mesh = tet_chain();
  const DofMap dofs = make_dof_map(mesh.vertex_count(), {0});
  BlockSparseMatrix matrix(stiffness_pattern(mesh, dofs));
  const auto slots = make_tet_slots(mesh, dofs, matrix);
  const int n = dofs.free_vertex_count();

  std::mt19937 rng(1);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int t = 0; t < mesh.tet_count(); ++t) {
    Eigen::Matrix<double, 12, 12> element;
    for (int i = 0; i < 144; ++i) element(i) = value(rng);
    const Tet& tet = mesh.tets[static_cast<size_t>(t)];
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const int slot = slots[static_cast<size_t>(t)][static_cast<size_t>(4 * a + b)];
        if (slot < 0) continue;
        matrix.block(slot) += element.block<3, 3>(3 * a, 3 * b);
        const int row = dofs.vertex_row[static_cast<size_t>(tet[static_cast<size_t>(a)])];
        const int col = dofs.vertex_row[static_cast<size_t>(tet[static_cast<size_t>(b)])];
        dense.block<3, 3>(3 * row, 3 * col) += element.block<3, 3>(3 * a, 3 * b);
      }
    }
  }
  Eigen::VectorXd x(3 * n);
  for (long i = 0; i < x.size(); ++i) x[i] = value(rng);
  Eigen::VectorXd y;
  matrix.multiply(x, y);
  EXPECT_LE((y - dense * x).norm(), 1e-12 * (dense * x).norm());
}

TEST(Assembly, RejectsInconsistentInput) {
  const TetMesh mesh = tet_chain();
  const DofMap dofs = make_dof_map(mesh.vertex_count(), {0});
  // A matrix lacking the blocks of tet 2 (pattern of the first two tets only).
  TetMesh first_two = mesh;
  first_two.tets.pop_back();
  const BlockSparseMatrix small(stiffness_pattern(first_two, dofs));
  EXPECT_THROW(make_tet_slots(mesh, dofs, small), std::invalid_argument);
  // A DOF map for another mesh, and a tet with a vertex out of range.
  EXPECT_THROW(stiffness_pattern(mesh, make_dof_map(4, {})), std::invalid_argument);
  TetMesh broken = mesh;
  broken.tets.push_back({0, 1, 2, 6});
  EXPECT_THROW(stiffness_pattern(broken, dofs), std::invalid_argument);
}

}  // namespace
}  // namespace tissue
