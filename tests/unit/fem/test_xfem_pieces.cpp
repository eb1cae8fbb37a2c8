// A tet cut into four pieces (issue 21, the virtual-node form of XfemElasticity): each piece a
// full-shape copy weighted by its volume fraction, its own vertex real and the others ghosts: copies
// with displacements of their own. The force is the gradient of the weighted energy; the tangent is the
// derivative of the force where it is exact (every piece moved rigidly, each its own way); pieces
// that coincide with the tet give the uncut tet's forces, shared out by weight.
#include "core/fem/corotational_kernel.hpp"
#include "core/material/material.hpp"
#include "core/fem/tet_element.hpp"
#include "core/fem/xfem_elasticity.hpp"
#include "core/system/block_sparse_matrix.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace tissue {
namespace {

constexpr int PIECES = 4;
constexpr int GHOST_ROWS = 12;                 // three ghosts per vertex: one in each piece it is not in
constexpr int BLOCK_ROWS = 4 + GHOST_ROWS;     // u of the four vertices, then the ghosts
constexpr int UNKNOWNS = 3 * BLOCK_ROWS;
using Vector = Eigen::Matrix<double, UNKNOWNS, 1>;
using Matrix = Eigen::Matrix<double, UNKNOWNS, UNKNOWNS>;

const TetPositions REST{Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.011, 0.001, -0.002),
                        Eigen::Vector3d(0.002, 0.009, 0.001), Eigen::Vector3d(-0.001, 0.002, 0.012)};
const std::array<double, PIECES> WEIGHTS{0.1, 0.2, 0.3, 0.4};

/// The ghost row of vertex j in piece p (p != j).
int ghost_row(int j, int p) { return 4 + 3 * j + (p < j ? p : p - 1); }

struct FourPieces {
  LameParameters lame = lame_parameters(Material{1.0e5, 0.4, 1000.0});
  TetRest rest = precompute_tet(REST);
  XfemElasticity xfem{{lame}, RotationSettings{.max_error_rad = 4e-18}};
  BlockSparseMatrix tangent;

  FourPieces() {
    std::vector<CutPiece> pieces(PIECES);
    for (int p = 0; p < PIECES; ++p) {
      pieces[static_cast<size_t>(p)].weight = WEIGHTS[static_cast<size_t>(p)];
      for (int j = 0; j < 4; ++j) {
        if (j == p) continue;
        pieces[static_cast<size_t>(p)].ghost_row[static_cast<size_t>(j)] = ghost_row(j, p);
      }
    }
    CutTet cut_tet;
    cut_tet.vertices = Tet{0, 1, 2, 3};
    cut_tet.rest_m = REST;
    xfem.add(cut_tet, pieces, rest, std::vector<Eigen::Matrix3d>(pieces.size(), Eigen::Matrix3d::Identity()));
    std::vector<std::vector<int>> pattern(BLOCK_ROWS);
    for (int r = 0; r < BLOCK_ROWS; ++r) {
      for (int c = 0; c < BLOCK_ROWS; ++c) pattern[static_cast<size_t>(r)].push_back(c);
    }
    tangent = BlockSparseMatrix(pattern);
    const std::span<const int> ghosts = xfem.ghost_rows(0);
    const int dofs = xfem.dof_count(0);
    const auto row_of = [&](int dof) { return dof < 4 ? dof : ghosts[static_cast<size_t>(dof - 4)]; };
    std::vector<std::uint8_t> coupled;
    xfem.coupled_dofs(0, coupled);
    for (int a = 0; a < dofs; ++a) {
      for (int b = 0; b < dofs; ++b) {
        const auto ab = static_cast<size_t>(dofs * a + b);
        xfem.slots(0)[ab] = coupled[ab] != 0 ? tangent.find_slot(row_of(a), row_of(b)) : -1;
      }
    }
  }

  /// Positions of the real vertices: rest + u.
  static Eigen::VectorXd positions(const Vector& q) {
    Eigen::VectorXd x(12);
    for (int j = 0; j < 4; ++j) x.segment<3>(3 * j) = REST[static_cast<size_t>(j)] + q.segment<3>(3 * j);
    return x;
  }

  Vector force(const Vector& q, bool with_tangent = false) {
    Eigen::VectorXd vertex_forces = Eigen::VectorXd::Zero(12);
    Eigen::VectorXd internal = Eigen::VectorXd::Zero(UNKNOWNS);
    const Eigen::VectorXd displacement = q;
    if (with_tangent) tangent.set_zero();
    xfem.evaluate(positions(q), displacement, vertex_forces, internal, with_tangent ? &tangent : nullptr);
    Vector f = internal;
    f.head<12>() = vertex_forces;
    return f;
  }
  double energy(const Vector& q) const { return xfem.elastic_energy_j(positions(q), Eigen::VectorXd(q)); }
  Matrix dense_tangent() const {
    Matrix k = Matrix::Zero();
    for (int r = 0; r < BLOCK_ROWS; ++r) {
      for (int c = 0; c < BLOCK_ROWS; ++c) {
        const int slot = tangent.find_slot(r, c);
        if (slot >= 0) k.block<3, 3>(3 * r, 3 * c) = tangent.block(slot);
      }
    }
    return k;
  }
};

/// Central differences, step 1e-7 m, of `value` (a scalar or a vector) in every unknown: column k is
/// the derivative in unknown k.
template <typename Value>
Eigen::MatrixXd central_differences(const Vector& q, Value value) {
  constexpr double STEP_M = 1e-7;
  Eigen::MatrixXd columns;
  for (int k = 0; k < UNKNOWNS; ++k) {
    Vector plus = q, minus = q;
    plus(k) += STEP_M;
    minus(k) -= STEP_M;
    const Eigen::VectorXd difference = (Eigen::VectorXd(value(plus)) - Eigen::VectorXd(value(minus))) / (2.0 * STEP_M);
    if (k == 0) columns.resize(difference.size(), UNKNOWNS);
    columns.col(k) = difference;
  }
  return columns;
}

// Every ghost on its real vertex (its displacement the vertex's): the four pieces are the tet itself,
// so each copy of vertex j gets w_p times the uncut tet's force there (vertex j's own u: w_j), and
// the copies' forces add up to the uncut tet's (the weights add up to 1).
TEST(XfemPieces, PiecesThatCoincideWithTheTetShareItsForcesByWeight) {
  FourPieces tet;
  Vector q = Vector::Zero();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.001, 0.001);
  for (int k = 0; k < 12; ++k) q(k) = jitter(rng);
  for (int j = 0; j < 4; ++j) {
    for (int p = 0; p < PIECES; ++p) {
      if (p != j) q.segment<3>(3 * ghost_row(j, p)) = q.segment<3>(3 * j);
    }
  }
  const Vector f = tet.force(q);
  TetPositions x;
  for (int j = 0; j < 4; ++j) x[static_cast<size_t>(j)] = REST[static_cast<size_t>(j)] + q.segment<3>(3 * j);
  const Eigen::Matrix3d deformation = deformation_gradient(tet.rest, x);
  const Eigen::Matrix<double, 3, 4> uncut = corotated_forces(tet.rest, rotation_by_svd(deformation), deformation, tet.lame);
  for (int j = 0; j < 4; ++j) {
    const Eigen::Vector3d own = WEIGHTS[static_cast<size_t>(j)] * uncut.col(j);
    EXPECT_LT((f.segment<3>(3 * j) - own).norm(), 1e-9 * uncut.norm()) << "vertex " << j;
    Eigen::Vector3d copies = f.segment<3>(3 * j);
    for (int p = 0; p < PIECES; ++p) {
      if (p == j) continue;
      const Eigen::Vector3d expected = WEIGHTS[static_cast<size_t>(p)] * uncut.col(j);
      EXPECT_LT((f.segment<3>(3 * ghost_row(j, p)) - expected).norm(), 1e-9 * uncut.norm()) << j << " in " << p;
      copies += f.segment<3>(3 * ghost_row(j, p));
    }
    EXPECT_LT((copies - uncut.col(j)).norm(), 1e-9 * uncut.norm()) << "vertex " << j;
  }
}

// The force is the gradient of sum_p w_p E(piece p) in all 48 unknowns, at a random state (central
// differences, step 1e-7 m: as test_xfem's two-part check, 1e-8 of |f|).
TEST(XfemPieces, ForceIsTheGradientOfTheWeightedEnergy) {
  FourPieces tet;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.002, 0.002);
  Vector q;
  for (int k = 0; k < UNKNOWNS; ++k) q(k) = jitter(rng);
  const Vector f = tet.force(q);
  const Eigen::VectorXd numeric = central_differences(q, [&](const Vector& at) {
    return Eigen::Matrix<double, 1, 1>(tet.energy(at));
  }).transpose();
  EXPECT_LT((numeric - f).norm(), 1e-8 * f.norm());
}

// Each piece moved rigidly, each with its own rotation: every piece's rotated strain vanishes, so the
// tangent is the exact derivative of the force (1e-6 relative, as for the two parts) and symmetric.
TEST(XfemPieces, TangentMatchesFiniteDifferencesWhenEveryPieceMovesRigidly) {
  FourPieces tet;
  std::array<Eigen::Matrix3d, PIECES> rotation;
  std::array<Eigen::Vector3d, PIECES> shift;
  for (int p = 0; p < PIECES; ++p) {
    rotation[static_cast<size_t>(p)] =
        Eigen::AngleAxisd(0.4 * (p + 1), Eigen::Vector3d(1.0, p, 2.0 - p).normalized()).toRotationMatrix();
    shift[static_cast<size_t>(p)] = Eigen::Vector3d(0.003 * p, -0.002, 0.001 * p);
  }
  const auto placed = [&](int p, int j) {
    return (rotation[static_cast<size_t>(p)] * REST[static_cast<size_t>(j)] + shift[static_cast<size_t>(p)]).eval();
  };
  Vector q = Vector::Zero();
  for (int j = 0; j < 4; ++j) q.segment<3>(3 * j) = placed(j, j) - REST[static_cast<size_t>(j)];  // in its own piece
  for (int j = 0; j < 4; ++j) {
    for (int p = 0; p < PIECES; ++p) {
      if (p == j) continue;
      q.segment<3>(3 * ghost_row(j, p)) = placed(p, j) - REST[static_cast<size_t>(j)];
    }
  }
  EXPECT_LT(tet.force(q).norm(), 1e-9);  // rigid pieces: no force
  tet.force(q, true);
  const Matrix analytic = tet.dense_tangent();
  const Eigen::MatrixXd numeric = central_differences(q, [&](const Vector& at) { return tet.force(at); });
  EXPECT_LT((numeric - analytic).norm(), 1e-6 * analytic.norm());
  EXPECT_LT((analytic - analytic.transpose()).norm(), 1e-12 * analytic.norm());
  // Ghosts of different pieces never meet (their blocks are absent); ghosts of one piece do.
  const std::span<const int> ghosts = tet.xfem.ghost_rows(0);
  const auto dof_of = [&](int row) {
    return 4 + static_cast<int>(std::find(ghosts.begin(), ghosts.end(), row) - ghosts.begin());
  };
  std::vector<std::uint8_t> coupled;
  tet.xfem.coupled_dofs(0, coupled);
  const auto couples = [&](int i, int j) { return coupled[static_cast<size_t>(tet.xfem.dof_count(0) * i + j)] != 0; };
  EXPECT_FALSE(couples(dof_of(ghost_row(1, 0)), dof_of(ghost_row(2, 1))));
  EXPECT_TRUE(couples(dof_of(ghost_row(1, 0)), dof_of(ghost_row(2, 0))));
  // A piece uses a vertex's u or its ghost, never both: piece 0 holds u of vertex 0 and ghosts of
  // the others, so u of vertex 1 meets no ghost of piece 0.
  EXPECT_TRUE(couples(0, dof_of(ghost_row(1, 0))));
  EXPECT_FALSE(couples(1, dof_of(ghost_row(2, 0))));
  EXPECT_EQ(tet.xfem.dof_count(0), BLOCK_ROWS);
}

// Each piece stretched (principal stretches 1.2-1.4 along axes of its own, far past
// TWIST_STIFFNESS_STRAIN) and turned its own way: R K R^T misses the stiffness of the pieces'
// twists, e_ab = 2 mu + 2 (lambda (tr S - 3) - 2 mu) / (s_a + s_b), all positive here, so with the
// twist terms the tangent is the exact derivative of the force (1e-6 relative, as for rigid pieces);
// without them it is off by the size of the stiffness itself (the 30 + 30 hatched frog's chips,
// strained so, turned past the Newton corrections' trigger in every step).
TEST(XfemPieces, TangentMatchesFiniteDifferencesWherePiecesAreStretchedAndTurned) {
  FourPieces tet;
  Vector q = Vector::Zero();
  const auto placed = [&](int p, int j) {
    const Eigen::Matrix3d axes =
        Eigen::AngleAxisd(0.3 + 0.5 * p, Eigen::Vector3d(p, 1.0, 1.0).normalized()).toRotationMatrix();
    const Eigen::Matrix3d stretch = axes * Eigen::Vector3d(1.4, 1.3 - 0.02 * p, 1.2).asDiagonal() * axes.transpose();
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(0.4 * (p + 1), Eigen::Vector3d(1.0, p, 2.0 - p).normalized()).toRotationMatrix();
    return (turn * stretch * REST[static_cast<size_t>(j)] + Eigen::Vector3d(0.003 * p, -0.002, 0.001 * p)).eval();
  };
  for (int j = 0; j < 4; ++j) q.segment<3>(3 * j) = placed(j, j) - REST[static_cast<size_t>(j)];
  for (int j = 0; j < 4; ++j) {
    for (int p = 0; p < PIECES; ++p) {
      if (p != j) q.segment<3>(3 * ghost_row(j, p)) = placed(p, j) - REST[static_cast<size_t>(j)];
    }
  }
  tet.force(q, true);
  const Matrix analytic = tet.dense_tangent();
  const Eigen::MatrixXd numeric = central_differences(q, [&](const Vector& at) { return tet.force(at); });
  std::printf("  |numeric - analytic| / |analytic| = %.2g\n", (numeric - analytic).norm() / analytic.norm());
  EXPECT_LT((numeric - analytic).norm(), 1e-6 * analytic.norm());
  EXPECT_LT((analytic - analytic.transpose()).norm(), 1e-12 * analytic.norm());
}

TEST(XfemPieces, BadPiecesAreRefused) {
  FourPieces tet;
  CutTet cut_tet;
  cut_tet.vertices = Tet{0, 1, 2, 3};
  const std::vector<Eigen::Matrix3d> identities(2, Eigen::Matrix3d::Identity());
  std::vector<CutPiece> one(1);
  one[0].weight = 1.0;
  EXPECT_THROW(tet.xfem.add(cut_tet, one, tet.rest, std::span(identities).first(1)), std::invalid_argument);
  std::vector<CutPiece> two(2);
  two[0].weight = 0.5;
  two[1].weight = 0.6;
  EXPECT_THROW(tet.xfem.add(cut_tet, two, tet.rest, identities), std::invalid_argument);
  two[1].weight = 0.5;
  two[1].ghost_row[0] = 7;
  EXPECT_THROW(tet.xfem.add(cut_tet, two, tet.rest, std::span(identities).first(1)), std::invalid_argument);
  EXPECT_EQ(tet.xfem.cut_tet_count(), 1);
}

// The assembly lists (set_assembly_lists: the uncut tets' phases, for a step's team): a cut tet whose
// tet has no list, a list past the phases' and a negative phase count are refused with nothing
// changed; the forces stay as they were.
TEST(XfemAssemblyLists, RefusesWhatNamesNoListAndKeepsTheForces) {
  FourPieces four;  // its cut tet names no mesh tet (-1)
  Vector q = Vector::Zero();
  for (int k = 0; k < UNKNOWNS; ++k) q(k) = 1e-4 * std::sin(1.0 + k);
  const Vector before = four.force(q);
  EXPECT_THROW(four.xfem.set_assembly_lists({0, 0}, 1), std::invalid_argument);  // tet -1
  EXPECT_THROW(four.xfem.set_assembly_lists({}, -1), std::invalid_argument);
  EXPECT_THROW(four.xfem.set_assembly_lists({3}, 1), std::invalid_argument);  // lists 0, 1 and 2
  // (Warm starts move on from call to call: the rotations agree to their 4e-18 rad, the forces to rounding.)
  EXPECT_LE((four.force(q) - before).norm(), 1e-12 * before.norm());

  XfemElasticity listed{{four.lame}, RotationSettings{}};
  listed.set_assembly_lists({0, 1}, 1);  // tet 0 in phase 0's first part, tet 1 in its second
  CutTet cut_tet;
  cut_tet.vertices = Tet{0, 1, 2, 3};
  cut_tet.rest_m = REST;
  cut_tet.cut.tet = 2;  // past the lists
  EXPECT_THROW(listed.add(cut_tet, four.rest, Eigen::Matrix3d::Identity()), std::invalid_argument);
  EXPECT_EQ(listed.cut_tet_count(), 0);
  cut_tet.cut.tet = 1;
  listed.add(cut_tet, four.rest, Eigen::Matrix3d::Identity());
  EXPECT_EQ(listed.cut_tet_count(), 1);
}

}  // namespace
}  // namespace tissue
