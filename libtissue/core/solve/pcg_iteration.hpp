// The preconditioned conjugate-gradient loop (internal to core/solve), written once for every
// preconditioner: PcgSolver passes Jacobi, CholeskyPcgSolver a lagged Cholesky factor.
//
// The products stream the compact copy of A (HalfMatrix, half_matrix.hpp), whose two parts are
// VectorParts'. The vectors are worked on in two parts of block rows of about equal matrix work (VectorParts);
// with a team of two threads each member takes one part of every mat-vec and vector update, and
// the dot products are the sum of the parts' dots in part order with one thread or two, so two
// threads give bitwise the iterates of one. A row-wise preconditioner (Jacobi) is applied part by
// part; another (a Cholesky factor) by the calling thread on the whole vector.
//
// The reported relative_residual is that of the recursively updated residual r_k, which CG
// carries anyway; it drifts from the true b - A x_k only by rounding (relative ~1e-15 * cond),
// far below any tolerance a real-time step uses, and checking it would cost one more product.
#pragma once

#include "core/solve/linear_solver.hpp"
#include "core/system/work_team.hpp"

#include <array>
#include <cmath>

namespace tissue {

/// Throws SolverError (prefixed by `who`) unless tolerance >= 0 (finite) and max_iterations >= 0.
void validate_pcg_settings(const PcgSolver::Settings& settings, const char* who);
/// 1 / diag(A), length rows() (resized if needed); throws SolverError for an entry <= 0 or not finite.
void jacobi_inverse_diagonal(const ShiftedSystem& system, Eigen::VectorXd& inverse_diagonal, const char* who);

/// A CG solver's LinearSolver::multiply_set_up: Y = A X through `work.matrix` (the copy the setup of
/// `set_up` assigned) on `team`'s members, if `system` is that one.
inline bool multiply_set_up_copy(const PcgWorkspace& work, const ShiftedSystem& set_up, WorkTeam* team,
                                 const ShiftedSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& x,
                                 RowMajorMatrix& y) {
  const bool same = set_up.stiffness != nullptr && set_up.stiffness == system.stiffness &&
                    set_up.stiffness_scale == system.stiffness_scale && set_up.diagonal == system.diagonal;
  if (!same || x.rows() != system.rows()) return false;
  work.matrix.multiply_columns(x, y, team);
  return true;
}

/// The rows of a system's vectors in PARTS consecutive parts (boundaries on block rows, balanced by
/// the matrix blocks of each part), and the team (or none) that works on them side by side.
class VectorParts {
 public:
  static constexpr int PARTS = MAX_STEP_THREADS;  // one per member of the largest team

  VectorParts(const BlockSparseMatrix& matrix, WorkTeam* team) : m_team(team) {
    for (int part = 0; part < PARTS; ++part) {
      m_first_block_row[static_cast<size_t>(part)] = matrix.balanced_row_split(part, PARTS);
    }
    m_first_block_row[PARTS] = matrix.block_rows();
  }
  [[nodiscard]] int first_block_row(int part) const { return m_first_block_row[static_cast<size_t>(part)]; }
  [[nodiscard]] int end_block_row(int part) const { return m_first_block_row[static_cast<size_t>(part) + 1]; }
  [[nodiscard]] long first(int part) const { return 3L * first_block_row(part); }
  [[nodiscard]] long count(int part) const { return 3L * (end_block_row(part) - first_block_row(part)); }

  /// job(part) for every part: side by side with a team of PARTS members, else in part order.
  template <class Job>
  void run(Job&& job) const {
    run_parts(m_team, PARTS, job);
  }

 private:
  WorkTeam* m_team;
  std::array<int, PARTS + 1> m_first_block_row{};
};

/// Per-part partial sums, added in part order (the same with one thread or two).
struct PartSums {
  std::array<double, VectorParts::PARTS> values{};
  [[nodiscard]] double total() const {
    double sum = 0.0;
    for (const double value : values) sum += value;
    return sum;
  }
};

/// CG's start: r = b - A x from the caller's x (a non-finite guess is replaced by zero; a zero guess,
/// the default step's, gives r = b without a product: one of a real-time step's eleven), the parts
/// of |r|^2 in `r_squared`; returns |r|. The rows no block joins to another (HalfMatrix::isolated_rows:
/// a part parked out of the field) are solved exactly first and r is zero there, where CG then
/// leaves them: within an iteration cap it would leave each off by p_k(1) times its start's error,
/// and nothing pulls such rows back together (a parked piece swelled as it fell).
inline double start_residual(const VectorParts& parts, const Eigen::VectorXd& b, const PartSums& b_squared,
                             Eigen::VectorXd& x, PcgWorkspace& work, PartSums& r_squared) {
  const auto segment = [&parts](auto& v, int part) { return v.segment(parts.first(part), parts.count(part)); };
  const std::vector<int>& isolated = work.matrix.isolated_rows();
  const bool zero_guess = (x.array() == 0.0).all();
  if (!isolated.empty() && x.allFinite()) work.matrix.solve_isolated_rows(b, x);
  if (zero_guess) {
    work.residual = b;
    r_squared = b_squared;
  } else {
    parts.run([&](int part) { work.matrix.multiply_part(x, work.product, part); });
    parts.run([&](int part) {
      work.matrix.finish_part(work.product, part);
      segment(work.residual, part) = segment(b, part) - segment(work.product, part);
      r_squared.values[static_cast<size_t>(part)] = segment(work.residual, part).squaredNorm();
    });
  }
  const bool finite = std::isfinite(std::sqrt(r_squared.total()));
  if (!finite) {
    x.setZero();
    work.residual = b;
    if (!isolated.empty()) work.matrix.solve_isolated_rows(b, x);
  }
  if (!isolated.empty() || !finite) {
    for (const int row : isolated) work.residual.segment<3>(3L * row).setZero();
    parts.run(
        [&](int part) { r_squared.values[static_cast<size_t>(part)] = segment(work.residual, part).squaredNorm(); });
  }
  return std::sqrt(r_squared.total());
}

/// Solves A x = b (A as work.matrix holds it: the caller's setup assigned it from `system`) from the
/// initial guess x (start_residual) until ||r|| <= tolerance * ||b|| or max_iterations. `precondition(r, z, first,
/// count)` sets z = P^-1 r for an SPD P: with ROW_WISE it is called for each part's rows (z_i depends on r_i only) and
/// must write only those; otherwise once for all rows (first 0, count rows()). z has r's length and is not r. Sizes
/// checked by the caller; `work` sized by it. `team`: nullptr, or two members that share the work (the results are
/// bitwise the same).
template <bool ROW_WISE, class Preconditioner>
SolveReport preconditioned_cg(const ShiftedSystem& system, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                              double tolerance, int max_iterations, PcgWorkspace& work, WorkTeam* team,
                              Preconditioner&& precondition) {
  SolveReport report;
  const VectorParts parts(*system.stiffness, team);
  const auto segment = [&parts](auto& v, int part) { return v.segment(parts.first(part), parts.count(part)); };
  PartSums b_squared, r_squared, rz_parts, curvature_parts;
  for (int part = 0; part < VectorParts::PARTS; ++part) {
    b_squared.values[static_cast<size_t>(part)] = segment(b, part).squaredNorm();
  }
  const double b_norm = std::sqrt(b_squared.total());
  if (b_norm == 0.0) {
    x.setZero();
    report.converged = true;
    return report;
  }

  double r_norm = start_residual(parts, b, b_squared, x, work, r_squared);
  const double threshold = tolerance * b_norm;
  report.relative_residual = r_norm / b_norm;
  if (work.residual_history != nullptr) work.residual_history->push_back(report.relative_residual);
  if (r_norm <= threshold) {
    report.converged = true;
    return report;
  }

  // z = P^-1 r and the parts of r . z (row-wise: inside the parts' jobs).
  auto precondition_part = [&](int part) {
    if constexpr (ROW_WISE) precondition(work.residual, work.preconditioned, parts.first(part), parts.count(part));
    rz_parts.values[static_cast<size_t>(part)] = segment(work.residual, part).dot(segment(work.preconditioned, part));
  };
  auto precondition_all = [&] {
    if constexpr (!ROW_WISE) {
      precondition(work.residual, work.preconditioned, 0L, work.residual.size());
      // CG leaves the isolated rows alone (a row-wise preconditioner gives zero from r's zero there).
      for (const int row : work.matrix.isolated_rows()) work.preconditioned.segment<3>(3L * row).setZero();
    }
    parts.run(precondition_part);
    return rz_parts.total();
  };

  double rz = precondition_all();
  work.direction = work.preconditioned;
  double alpha = 0.0;
  double beta = 0.0;
  for (int k = 1; k <= max_iterations; ++k) {
    parts.run([&](int part) { work.matrix.multiply_part(work.direction, work.product, part); });
    parts.run([&](int part) {
      work.matrix.finish_part(work.product, part);
      curvature_parts.values[static_cast<size_t>(part)] = segment(work.direction, part).dot(segment(work.product, part));
    });
    const double curvature = curvature_parts.total();
    // Breakdown: A is not positive definite along p (or the values are not finite). Keep the
    // last iterate and say so; the caller decides whether to accept it.
    if (!(curvature > 0.0) || !std::isfinite(curvature)) break;
    alpha = rz / curvature;
    parts.run([&](int part) {
      segment(x, part) += alpha * segment(work.direction, part);
      segment(work.residual, part) -= alpha * segment(work.product, part);
      r_squared.values[static_cast<size_t>(part)] = segment(work.residual, part).squaredNorm();
      if constexpr (ROW_WISE) precondition_part(part);
    });
    r_norm = std::sqrt(r_squared.total());
    report.iterations = k;
    report.relative_residual = r_norm / b_norm;
    if (work.residual_history != nullptr) work.residual_history->push_back(report.relative_residual);
    if (r_norm <= threshold) {
      report.converged = true;
      break;
    }
    if (!std::isfinite(r_norm)) break;
    const double rz_next = ROW_WISE ? rz_parts.total() : precondition_all();
    beta = rz_next / rz;
    rz = rz_next;
    parts.run([&](int part) {
      segment(work.direction, part) = segment(work.preconditioned, part) + beta * segment(work.direction, part);
    });
  }
  return report;
}

}  // namespace tissue
