// Test systems for the linear solvers: an SPD A = s K + diag(d) where K is a sum of 3x3 SPD
// "spring" terms over the edges of a grid (so K is PSD, like an unconstrained stiffness), kept
// both as a BlockSparseMatrix and as a dense Eigen reference.
#pragma once

#include "core/solve/linear_solver.hpp"

#include <Eigen/Dense>

#include <random>
#include <utility>
#include <vector>

namespace tissue::test {

struct TestSystem {
  BlockSparseMatrix stiffness;
  Eigen::VectorXd diagonal;
  Eigen::MatrixXd dense_stiffness;

  [[nodiscard]] Eigen::MatrixXd dense(double scale) const {
    Eigen::MatrixXd a = scale * dense_stiffness;
    a.diagonal() += diagonal;
    return a;
  }
  [[nodiscard]] ShiftedSystem shifted(double scale) const { return {&stiffness, scale, &diagonal}; }

  /// Adds the PSD term [B -B; -B B] on block rows (i, j); the four blocks must exist.
  void add_edge(int i, int j, const Eigen::Matrix3d& b) {
    stiffness.block(stiffness.find_slot(i, i)) += b;
    stiffness.block(stiffness.find_slot(j, j)) += b;
    stiffness.block(stiffness.find_slot(i, j)) -= b;
    stiffness.block(stiffness.find_slot(j, i)) -= b;
    if (dense_stiffness.size() == 0) return;  // large systems go without the dense reference
    dense_stiffness.block<3, 3>(3 * i, 3 * i) += b;
    dense_stiffness.block<3, 3>(3 * j, 3 * j) += b;
    dense_stiffness.block<3, 3>(3 * i, 3 * j) -= b;
    dense_stiffness.block<3, 3>(3 * j, 3 * i) -= b;
  }
};

/// A random symmetric positive definite 3x3 block with eigenvalues in [lo, hi].
inline Eigen::Matrix3d random_spd_block(std::mt19937& rng, double lo = 0.5, double hi = 2.0) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> eigen(lo, hi);
  const Eigen::Matrix3d q =
      Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
  return q * Eigen::Vector3d(eigen(rng), eigen(rng), eigen(rng)).asDiagonal() * q.transpose();
}

inline Eigen::VectorXd random_vector(long n, std::mt19937& rng) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::VectorXd v(n);
  for (long i = 0; i < n; ++i) v[i] = value(rng);
  return v;
}

/// Appends a block row coupled to `neighbour` by a random SPD edge, as the XFEM enrichment grows the
/// system (rows at the end); the appended row's d is 0.07.
inline void append_coupled_row(TestSystem& system, int neighbour, std::mt19937& rng) {
  const int row = system.stiffness.append_block_row();
  system.stiffness.insert_block(row, neighbour);
  system.stiffness.insert_block(neighbour, row);
  const long n = system.stiffness.rows();
  Eigen::MatrixXd grown = Eigen::MatrixXd::Zero(n, n);
  grown.topLeftCorner(n - 3, n - 3) = system.dense_stiffness;
  system.dense_stiffness = grown;
  system.diagonal.conservativeResize(n);
  system.diagonal.tail<3>().setConstant(0.07);
  system.add_edge(row, neighbour, random_spd_block(rng));
}

/// Grid of nx*ny*nz block rows, edges to the +x, +y, +z and +x+y neighbours; d in [0.5, 1.5] * mass.
/// `with_dense` = false leaves dense_stiffness empty (for systems too large for a dense reference).
inline TestSystem make_grid_system(int nx, int ny, int nz, unsigned seed, double mass = 0.05,
                                   BlockSparseMatrix::Reserve reserve = {}, bool with_dense = true) {
  const int n = nx * ny * nz;
  const auto index = [nx, ny](int x, int y, int z) { return x + nx * (y + ny * z); };
  std::vector<std::pair<int, int>> edges;
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        if (x + 1 < nx) edges.emplace_back(index(x, y, z), index(x + 1, y, z));
        if (y + 1 < ny) edges.emplace_back(index(x, y, z), index(x, y + 1, z));
        if (z + 1 < nz) edges.emplace_back(index(x, y, z), index(x, y, z + 1));
        if (x + 1 < nx && y + 1 < ny) edges.emplace_back(index(x, y, z), index(x + 1, y + 1, z));
      }
    }
  }
  std::vector<std::vector<int>> pattern(static_cast<size_t>(n));
  for (const auto& [i, j] : edges) {
    pattern[static_cast<size_t>(i)].push_back(j);
    pattern[static_cast<size_t>(j)].push_back(i);
  }
  TestSystem system{BlockSparseMatrix(pattern, reserve), Eigen::VectorXd(3 * n),
                    with_dense ? Eigen::MatrixXd::Zero(3 * n, 3 * n) : Eigen::MatrixXd()};
  std::mt19937 rng(seed);
  for (const auto& [i, j] : edges) system.add_edge(i, j, random_spd_block(rng));
  std::uniform_real_distribution<double> mass_factor(0.5, 1.5);
  for (long k = 0; k < system.diagonal.size(); ++k) system.diagonal[k] = mass * mass_factor(rng);
  return system;
}

}  // namespace tissue::test
