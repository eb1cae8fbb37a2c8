// Linear solvers behind one interface. The system matrix of every integrator here has the form
//   A = stiffness_scale * K + diag(d)
// with K a symmetric 3x3-block sparse matrix (tangent stiffness) and d > 0 (scaled lumped mass,
// plus mass damping), so A is SPD whenever K is positive semi-definite. Backward Euler uses
// stiffness_scale = h*beta + h^2, d = (1 + h*alpha) m; IDA's Newton matrix has the same shape.
#pragma once

#include "core/system/block_sparse_matrix.hpp"

#include <Eigen/Core>

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>

namespace tissue {

struct ShiftedSystem {
  const BlockSparseMatrix* stiffness = nullptr;  ///< K (rows() x rows())
  double stiffness_scale = 1.0;
  const Eigen::VectorXd* diagonal = nullptr;  ///< d, length stiffness->rows()

  [[nodiscard]] int rows() const { return stiffness->rows(); }
  /// y = A x. No allocation. x and y must be different vectors.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  /// Throws SolverError unless K and d are set, and d, b and x all have length rows().
  void check_sizes(const Eigen::VectorXd& b, const Eigen::VectorXd& x) const;
};

struct SolveReport {
  int iterations = 0;              ///< PCG iterations (0 for a direct solve)
  double relative_residual = 0.0;  ///< ||b - A x|| / ||b|| at exit (0 if b == 0)
  bool converged = false;          ///< PCG: tolerance reached; CHOLMOD: factorization succeeded
};

/// A solve that cannot be done at all (matrix not positive definite for CHOLMOD, sizes wrong).
class SolverError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  /// Solves A x = b. On entry x holds the initial guess (iterative solvers warm-start from it;
  /// it must have length A.rows()). Work buffers are kept between calls: no allocation while the
  /// size stays the same.
  virtual SolveReport solve(const ShiftedSystem& system, const Eigen::VectorXd& b, Eigen::VectorXd& x) = 0;
  [[nodiscard]] virtual std::string_view name() const = 0;
};

/// Jacobi-preconditioned conjugate gradients. Stops when ||r|| <= tolerance * ||b|| or after
/// max_iterations (then converged = false; x is the last iterate, which a real-time loop accepts).
class PcgSolver final : public LinearSolver {
 public:
  struct Settings {
    double tolerance = 1e-6;
    int max_iterations = 10000;
  };
  explicit PcgSolver(Settings settings);
  SolveReport solve(const ShiftedSystem& system, const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] std::string_view name() const override { return "pcg"; }
  [[nodiscard]] const Settings& settings() const { return m_settings; }

 private:
  Settings m_settings;
  Eigen::VectorXd m_residual, m_direction, m_preconditioned, m_product, m_inverse_diagonal;
};

/// Sparse Cholesky (SuiteSparse CHOLMOD, supernodal). The symbolic analysis (ordering, pattern of L)
/// is computed once and reused while K.pattern_revision() and the size are unchanged; each solve
/// refactorizes numerically. Throws SolverError if A is not positive definite.
class CholmodSolver final : public LinearSolver {
 public:
  CholmodSolver();
  ~CholmodSolver() override;
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;
  SolveReport solve(const ShiftedSystem& system, const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] std::string_view name() const override { return "cholmod"; }

  /// Factor once, solve many (the contact stiffness needs three solves with one A): factorizes A
  /// (reusing the symbolic analysis as solve() does) for solve_factored(). Throws SolverError if A
  /// is not positive definite or the sizes are wrong; the previous factor is then gone.
  void factorize(const ShiftedSystem& system);
  /// Solves A x = b with the factor of the last factorize() (or of the last solve() with b != 0;
  /// a solve() with b == 0 factorizes nothing and drops the factor). x is resized to A.rows().
  /// Throws SolverError when there is no factor, b has the wrong length or x is not finite.
  void solve_factored(const Eigen::VectorXd& b, Eigen::VectorXd& x);
  /// Whether solve_factored() has a factor to use.
  [[nodiscard]] bool has_factor() const;

  /// How many symbolic analyses were done so far (tests check it is reused).
  [[nodiscard]] int symbolic_analysis_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace tissue
