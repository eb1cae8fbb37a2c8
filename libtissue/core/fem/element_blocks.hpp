// How one element (an uncut tet, or a piece of a cut tet) adds its tangent blocks to K: through its
// 16 slots (TetSlots: block (i, j) of its four local vertices at [4 i + j], -1 where no block is
// stored), shared by the uncut model (corotational.cpp) and the XFEM pieces (xfem_elasticity.cpp).
//
// The lanes kernel is always inlined into the callers' TISSUE_HOT_KERNEL clones: -Wpsabi's note (a
// 32-byte vector passed or returned without AVX) concerns calls that never happen. GCC issues it
// while it generates the clones, at the end of the including file, so it stays off from here to
// the end of the two files that include this (clang warns alike).
#pragma once

#include "core/fem/corotational_kernel.hpp"
#include "core/material/material.hpp"
#include "core/system/assembly.hpp"
#include "core/system/block_sparse_matrix.hpp"

#include <Eigen/Core>

#include <array>
#include <cstring>

#pragma GCC diagnostic ignored "-Wpsabi"  // (clang too)

namespace tissue::element_blocks {

/// Adds an element's tangent blocks through its slots: block(i, j) for i <= j (and its transpose at
/// (j, i)), skipping blocks that touch a fixed vertex (slot -1), so a block is computed only where
/// it is stored.
template <class Block>
void add_blocks(const TetSlots& slots, BlockSparseMatrix& tangent, Block block) {
  for (int i = 0; i < 4; ++i) {
    for (int j = i; j < 4; ++j) {
      const int slot_ij = slots[static_cast<size_t>(4 * i + j)];
      if (slot_ij < 0) continue;
      const Eigen::Matrix3d b = block(i, j);
      tangent.add_block(slot_ij, b);
      if (i != j) tangent.add_block_transposed(slots[static_cast<size_t>(4 * j + i)], b);
    }
  }
}

/// A column in lanes (corotational_kernel.hpp); lane 3 of a column is zero.
using Lanes = ColumnLanes;

/// A block's nine values (column-major) += low (values 0-3), high (4-7) and last (8): the same
/// loads and stores for every add of this kernel to a block, so that the next element's loads take
/// the last one's stores whole (docs/DESIGN.md, "Blocks are added entry by entry").
[[gnu::always_inline]] inline void add_block_lanes(double* to, Lanes low, Lanes high, double last) {
  Lanes value_low, value_high;
  std::memcpy(&value_low, to, sizeof(Lanes));
  std::memcpy(&value_high, to + 4, sizeof(Lanes));
  value_low += low;
  value_high += high;
  std::memcpy(to, &value_low, sizeof(Lanes));
  std::memcpy(to + 4, &value_high, sizeof(Lanes));
  to[8] += last;
}

/// rotated_stiffness_block's blocks of one element of volume `volume_m3` (a piece's: its tet's times
/// its weight) and rest shape gradients g, R K_ij R^T = V [lambda c_i c_j^T + mu c_j c_i^T +
/// mu (g_i . g_j) I], added through its slots as add_blocks does, each column in lanes: column k of
/// block (i, j) is (lambda V c_i) c_j[k] + (mu V c_j) c_i[k] + mu V (g_i . g_j) e_k, and block (j, i)
/// its exact transpose (the lanes shuffled).
[[gnu::always_inline]] inline void add_rotated_stiffness_blocks(const TetSlots& slots, BlockSparseMatrix& tangent,
                                                                const Eigen::Matrix<double, 3, 4>& g,
                                                                const LameParameters& lame, double volume_m3,
                                                                const Eigen::Matrix3d& rotation) {
  const double lambda_v = lame.lambda_pa * volume_m3;
  const double mu_v = lame.mu_pa * volume_m3;
  // c = R g, each column made in lanes from R's columns (read from memory as scalars: lanes put
  // together on the stack would be loaded whole from pieces stored apart, the stall above).
  const Lanes r0{rotation(0, 0), rotation(1, 0), rotation(2, 0), 0.0};
  const Lanes r1{rotation(0, 1), rotation(1, 1), rotation(2, 1), 0.0};
  const Lanes r2{rotation(0, 2), rotation(1, 2), rotation(2, 2), 0.0};
  std::array<Lanes, 4> column{}, lambda_column{}, mu_column{};
  for (int i = 0; i < 4; ++i) {
    column[static_cast<size_t>(i)] = r0 * g(0, i) + r1 * g(1, i) + r2 * g(2, i);
    lambda_column[static_cast<size_t>(i)] = lambda_v * column[static_cast<size_t>(i)];
    mu_column[static_cast<size_t>(i)] = mu_v * column[static_cast<size_t>(i)];
  }
  for (int i = 0; i < 4; ++i) {
    const Lanes& c_i = column[static_cast<size_t>(i)];
    const Lanes& lambda_c_i = lambda_column[static_cast<size_t>(i)];
    for (int j = i; j < 4; ++j) {
      const int slot_ij = slots[static_cast<size_t>(4 * i + j)];
      if (slot_ij < 0) continue;
      const Lanes& c_j = column[static_cast<size_t>(j)];
      const Lanes& mu_c_j = mu_column[static_cast<size_t>(j)];
      const double diagonal = mu_v * g.col(i).dot(g.col(j));
      const Lanes column0 = lambda_c_i * c_j[0] + mu_c_j * c_i[0] + Lanes{diagonal, 0.0, 0.0, 0.0};
      const Lanes column1 = lambda_c_i * c_j[1] + mu_c_j * c_i[1] + Lanes{0.0, diagonal, 0.0, 0.0};
      const Lanes column2 = lambda_c_i * c_j[2] + mu_c_j * c_i[2] + Lanes{0.0, 0.0, diagonal, 0.0};
      add_block_lanes(tangent.block(slot_ij).data(), __builtin_shufflevector(column0, column1, 0, 1, 2, 4),
                      __builtin_shufflevector(column1, column2, 1, 2, 4, 5), column2[2]);
      if (i == j) continue;
      // The transpose's values in storage order: (c0[0] c1[0] c2[0] c0[1]) (c1[1] c2[1] c0[2] c1[2]) c2[2].
      const Lanes first_rows = __builtin_shufflevector(column0, column1, 0, 4, 1, 5);  // c0[0] c1[0] c0[1] c1[1]
      const Lanes last_rows = __builtin_shufflevector(column1, column2, 1, 5, 2, 6);   // c1[1] c2[1] c1[2] c2[2]
      add_block_lanes(tangent.block(slots[static_cast<size_t>(4 * j + i)]).data(),
                      __builtin_shufflevector(first_rows, column2, 0, 1, 4, 2),
                      __builtin_shufflevector(last_rows, column0, 0, 1, 6, 2), column2[2]);
    }
  }
}

}  // namespace tissue::element_blocks
