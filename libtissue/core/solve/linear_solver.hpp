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

/// Setup and solve are split: an integrator sets up once per matrix and may solve several times
/// (a Newton iteration, the contact stiffness's three columns).
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  /// Prepares solves with A: PCG takes its Jacobi preconditioner, CHOLMOD factorizes numerically
  /// (reusing the symbolic analysis while K's pattern is unchanged). K and d must stay alive and
  /// unchanged until the next setup(). Throws SolverError (A not positive definite, sizes wrong);
  /// nothing is set up then.
  virtual void setup(const ShiftedSystem& system) = 0;
  /// Solves A x = b with the A of the last setup(). On entry x holds the initial guess (iterative
  /// solvers warm-start from it and need length A.rows(); a direct solver resizes it). Work buffers
  /// are kept between calls: no allocation while the size stays the same. Throws SolverError
  /// without a setup, for a wrong length or a non-finite direct solution.
  virtual SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) = 0;
  /// setup(system), then solve(b, x).
  SolveReport solve(const ShiftedSystem& system, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    setup(system);
    return solve(b, x);
  }
  /// Whether solve(b, x) has an A to use.
  [[nodiscard]] virtual bool is_set_up() const = 0;
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
  using LinearSolver::solve;
  void setup(const ShiftedSystem& system) override;
  SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] bool is_set_up() const override { return m_system.stiffness != nullptr; }
  [[nodiscard]] std::string_view name() const override { return "pcg"; }
  [[nodiscard]] const Settings& settings() const { return m_settings; }

 private:
  Settings m_settings;
  ShiftedSystem m_system{nullptr, 1.0, nullptr};  // of the last setup()
  Eigen::VectorXd m_residual, m_direction, m_preconditioned, m_product, m_inverse_diagonal;
};

/// Sparse Cholesky (SuiteSparse CHOLMOD, supernodal). The symbolic analysis (ordering, pattern of L)
/// is computed once and reused while K.pattern_revision() and the size are unchanged; each setup()
/// refactorizes numerically (throws SolverError if A is not positive definite), and any number of
/// solves use that factor (the contact stiffness needs three with one A).
class CholmodSolver final : public LinearSolver {
 public:
  CholmodSolver();
  ~CholmodSolver() override;
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;
  using LinearSolver::solve;
  /// Factorizes A; the previous factor is gone even when this throws.
  void setup(const ShiftedSystem& system) override;
  /// x = A^-1 b with the factor; reports the true relative residual (one product with A).
  SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] bool is_set_up() const override;
  [[nodiscard]] std::string_view name() const override { return "cholmod"; }

  /// How many symbolic analyses were done so far (tests check it is reused).
  [[nodiscard]] int symbolic_analysis_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace tissue
