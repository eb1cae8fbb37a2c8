// Linear solvers behind one interface. The system matrix of every integrator here has the form
//   A = stiffness_scale * K + diag(d)
// with K a symmetric 3x3-block sparse matrix (tangent stiffness) and d > 0 (scaled lumped mass,
// plus mass damping), so A is SPD whenever K is positive semi-definite. Backward Euler uses
// stiffness_scale = h*beta + h^2, d = (1 + h*alpha) m; IDA's Newton matrix has the same shape.
#pragma once

#include "core/solve/half_matrix.hpp"
#include "core/system/block_sparse_matrix.hpp"
#include "core/system/work_team.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace tissue {

struct ShiftedSystem {
  const BlockSparseMatrix* stiffness = nullptr;  ///< K (rows() x rows())
  double stiffness_scale = 1.0;
  const Eigen::VectorXd* diagonal = nullptr;  ///< d, length stiffness->rows()
  /// Optional (nullptr: none): per block row, the rotation K's rows have turned through since the
  /// rest state (DynamicsModel::block_frames); given to solvers that follow_block_frames().
  const std::vector<Eigen::Matrix3d>* block_frames = nullptr;
  /// Optional (nullptr: none): per block row, the point its unknowns move [m] (DynamicsModel::
  /// block_positions); given to solvers that use_block_positions().
  const std::vector<Eigen::Vector3d>* block_positions = nullptr;
  /// Optional (nullptr: none): per block row, nonzero where the row left the dynamics
  /// (DynamicsModel::rows_left: a part parked out of the field; read with row_left()). Those
  /// of them no nonzero block of K joins to another are each solved exactly by the CG solvers
  /// (HalfMatrix::isolated_rows).
  const std::vector<std::uint8_t>* rows_left = nullptr;

  [[nodiscard]] int rows() const { return stiffness->rows(); }
  /// y = A x. No allocation. x and y must be different vectors.
  void multiply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const;
  /// The block rows [first_block_row, end_block_row) of y = A x (y has length rows() already).
  void multiply_rows(const Eigen::VectorXd& x, Eigen::VectorXd& y, int first_block_row, int end_block_row) const;
  /// Throws SolverError ("<who>: ...") unless K and d are set and d has length rows().
  void check(std::string_view who) const;
  /// Throws SolverError unless check() passes and b and x have length rows().
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
  /// setup() for an A close to the last setup's (a Newton correction's matrix within the step that
  /// set up): same K object, pattern and size, values moved a little. A direct solver may keep its
  /// factor and iterate on A with it as the preconditioner (CholmodSolver: to a relative residual
  /// of 1e-6, or a forcing term with solve_roughly()); the others set up as usual.
  virtual void setup_nearby(const ShiftedSystem& system) { setup(system); }
  /// Solves A x = b with the A of the last setup(). On entry x holds the initial guess (iterative
  /// solvers warm-start from it and need length A.rows(); a direct solver resizes it). Work buffers
  /// are kept between calls: no allocation while the size stays the same. Throws SolverError
  /// without a setup, for a wrong length or a non-finite direct solution.
  virtual SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) = 0;
  /// After setup_nearby(), for a Newton correction: a solve good to a forcing term (x from zero),
  /// which is all a correction needs while the iterations go on. A solver that keeps its factor
  /// across setup_nearby() stops there (CholmodSolver: a relative residual of 1e-2); the others
  /// solve as solve() does.
  virtual SolveReport solve_roughly(const Eigen::VectorXd& b, Eigen::VectorXd& x) { return solve(b, x); }
  /// Carries x from solve_roughly() on to the accuracy of solve() (a correction that turned out
  /// converged, the step's last). Reports the iterations it added; for the others, none (x is
  /// solve()'s already).
  virtual SolveReport refine(const Eigen::VectorXd& /*b*/, Eigen::VectorXd& /*x*/) {
    return SolveReport{0, 0.0, true};
  }
  /// Whether solve_roughly() can stop short of solve() (then refine() has something to do).
  [[nodiscard]] virtual bool solves_roughly() const { return false; }
  /// setup(system), then solve(b, x).
  SolveReport solve(const ShiftedSystem& system, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    setup(system);
    return solve(b, x);
  }
  /// Whether solve(b, x) has an A to use.
  [[nodiscard]] virtual bool is_set_up() const = 0;
  /// Y = A X for `system` when the last setup() was of it (the same K, scale and d), for products
  /// beside the solve (the warm start's, galerkin_start): the CG solvers through the compact copy
  /// their products stream (half of K's blocks, single precision at real-time tolerances), all of X's
  /// columns in one pass over it (HalfMatrix::multiply_columns), on the lent team, and true; false (Y
  /// untouched) for the others and another system: then ShiftedSystem::multiply. X and Y must differ.
  virtual bool multiply_set_up(const ShiftedSystem& /*system*/, const Eigen::Ref<const Eigen::MatrixXd>& /*x*/,
                               RowMajorMatrix& /*y*/) const {
    return false;
  }
  /// Lends the solver a team of threads for its solves until lent nullptr (an integrator lends its
  /// step's team for the step only). The CG solvers split their products and vector updates over
  /// it, with bitwise the results of one thread; CHOLMOD ignores it.
  virtual void lend_work_team(WorkTeam* /*team*/) {}
  /// Drops what earlier setups left for later ones (CholeskyPcgSolver: its lagged factor and a
  /// refresh in flight), so that the next setup starts as a fresh solver's would. Called where a
  /// state is saved and where it is restored (Integrator::restart), so that a restored run
  /// continues bitwise as the saved one did. The other solvers keep nothing: no-op.
  virtual void forget_earlier_setups() {}
  /// Whether the solver uses ShiftedSystem::block_frames (an integrator asks the model for them
  /// only then: they cost a pass over the mesh).
  [[nodiscard]] virtual bool follows_block_frames() const { return false; }
  /// Whether the solver uses ShiftedSystem::block_positions (asked of the model only then).
  [[nodiscard]] virtual bool uses_block_positions() const { return false; }
  [[nodiscard]] virtual std::string_view name() const = 0;
};

/// Conjugate gradients' vectors, kept between solves so that a solve of an unchanged size does not allocate.
struct PcgWorkspace {
  Eigen::VectorXd residual, direction, preconditioned, product;
  HalfMatrix matrix;  ///< A as the products stream it, made at each setup
  /// Where each solve appends its relative residual after every iteration (iteration 0 first); the
  /// solvers' record_residuals(). For plots and benchmarks: nullptr (the default) records nothing.
  std::vector<double>* residual_history = nullptr;

  void resize(long n) {
    if (residual.size() == n) return;
    residual.resize(n);
    direction.resize(n);
    preconditioned.resize(n);
    product.resize(n);
  }
};

/// Jacobi-preconditioned conjugate gradients. Stops when ||r|| <= tolerance * ||b|| or after
/// max_iterations (then converged = false; x is the last iterate, which a real-time loop accepts).
class PcgSolver final : public LinearSolver {
 public:
  struct Settings {
    double tolerance = 1e-6;
    int max_iterations = 10000;
    /// The entries of A the products stream (half_matrix.hpp): single halves the bytes again, and
    /// changes a 200-step run by ~1e-7 relative (docs/BENCHMARKS.md, issue 23); automatic takes it
    /// for tolerances >= 1e-5 (the real-time setting is 1e-3).
    MatrixPrecision matrix_precision = MatrixPrecision::automatic;
  };
  explicit PcgSolver(Settings settings);
  using LinearSolver::solve;
  void setup(const ShiftedSystem& system) override;
  SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] bool is_set_up() const override { return m_system.stiffness != nullptr; }
  [[nodiscard]] std::string_view name() const override { return "pcg"; }
  void lend_work_team(WorkTeam* team) override { m_team = team; }
  bool multiply_set_up(const ShiftedSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& x,
                       RowMajorMatrix& y) const override;
  [[nodiscard]] const Settings& settings() const { return m_settings; }
  /// Appends the relative residual ||r_k|| / ||b|| of every iteration k >= 0 of the solves that
  /// follow to `history` (kept by the caller; nullptr stops). For convergence plots.
  void record_residuals(std::vector<double>* history) { m_work.residual_history = history; }

 private:
  Settings m_settings;
  ShiftedSystem m_system{nullptr, 1.0, nullptr};  // of the last setup()
  PcgWorkspace m_work;
  Eigen::VectorXd m_inverse_diagonal;
  WorkTeam* m_team = nullptr;  // lent for a step
};

class TwoLevelPreconditioner;

/// Conjugate gradients with a two-level preconditioner: Jacobi plus an exact solve on the rigid
/// motions (translations and rotations) of small aggregates of block rows
/// (two_level_preconditioner.hpp). Each iteration resolves the slow motions that Jacobi alone
/// leaves for hundreds of iterations (a freed piece's fall, a cantilever's sag), and nothing is
/// factorized but the small coarse matrix, so a cut costs no large factorization. The aggregates
/// are made at the first setup and again when K's pattern changes (a cut); the coarse matrix then
/// and every few setups. Uses ShiftedSystem::block_positions (translations only without them).
/// Stopping rule and reported residual as PcgSolver's.
class TwoLevelPcgSolver final : public LinearSolver {
 public:
  explicit TwoLevelPcgSolver(PcgSolver::Settings settings);
  ~TwoLevelPcgSolver() override;
  TwoLevelPcgSolver(const TwoLevelPcgSolver&) = delete;
  TwoLevelPcgSolver& operator=(const TwoLevelPcgSolver&) = delete;
  using LinearSolver::solve;
  void setup(const ShiftedSystem& system) override;
  /// Keeps the last setup's coarse level (a Newton correction's matrix is the step's, moved a
  /// little): only the Jacobi diagonal and A's copy are taken anew.
  void setup_nearby(const ShiftedSystem& system) override;
  SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] bool is_set_up() const override { return m_system.stiffness != nullptr; }
  [[nodiscard]] std::string_view name() const override { return "pcgTwoLevel"; }
  void lend_work_team(WorkTeam* team) override { m_team = team; }
  bool multiply_set_up(const ShiftedSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& x,
                       RowMajorMatrix& y) const override;
  /// The aggregates are made anew at the next setup, as in a fresh solver.
  void forget_earlier_setups() override;
  [[nodiscard]] bool uses_block_positions() const override { return true; }
  [[nodiscard]] const PcgSolver::Settings& settings() const { return m_settings; }
  /// As PcgSolver::record_residuals.
  void record_residuals(std::vector<double>* history) { m_work.residual_history = history; }
  /// Of the last setup: aggregates and columns of the coarse space (0 if its factorization failed).
  [[nodiscard]] int aggregate_count() const;
  [[nodiscard]] int coarse_size() const;

 private:
  PcgSolver::Settings m_settings;
  ShiftedSystem m_system{nullptr, 1.0, nullptr};  // of the last setup()
  PcgWorkspace m_work;
  Eigen::VectorXd m_inverse_diagonal;
  std::unique_ptr<TwoLevelPreconditioner> m_preconditioner;
  WorkTeam* m_team = nullptr;  // lent for a step

  void set_up(const ShiftedSystem& system, bool nearby);
};

/// Conjugate gradients preconditioned by the Cholesky factor of an earlier A (a lagged factor).
/// On the frog a factorization costs as much as ~60 solves with the factor, and A changes little
/// from one step to the next, so the factor is kept while it works and rebuilt off the critical path:
/// * A setup without a usable factor (the first; A smaller than the factor, or another matrix)
///   factorizes A at once and throws SolverError if A is not positive definite.
/// * A refresh (a factor of the A of the setup that starts it, values copied then) starts when K's
///   size or block pattern differs from the factor's (a cut, without `refactor_on_growth`), or when
///   the last solve needed more than
///   `refresh_iterations` iterations or did not converge. It is factorized in a worker thread
///   (`background_refactor`) or, without one, at pick-up; either way the setup `pickup_setups` setups
///   after the start installs it (waiting for the worker if need be), so the results are bitwise the
///   same whatever the machine's speed and with or without the thread. One refresh at a time.
/// * With `refactor_on_growth` (the default) a setup whose K changed its pattern or size factorizes A
///   at once. Without it, while the factor covers fewer rows than A (a cut appended rows at the end),
///   the preconditioner is block diagonal: the factor on the first rows, Jacobi (1 / diag A) on the
///   appended ones, until the refresh lands.
/// * A refresh that fails (not positive definite) is counted and the old factor kept.
/// A setup or solve that does not start or install a refresh allocates nothing. Stopping rule and
/// reported residual as PcgSolver's.
class CholeskyPcgSolver final : public LinearSolver {
 public:
  struct Refresh {
    /// A solve needing more iterations than this asks for a new factor. A fixed count, not a multiple
    /// of the first solve's: that one is 1-2 iterations with a fresh factor, and a fixed count bounds
    /// the step's cost (frog: an iteration ~0.12 ms, 10 of them a quarter of a factorization).
    int refresh_iterations = 10;
    /// A refresh is installed by the setup this many setups after the one that started it (>= 1).
    /// 2 leaves the worker a whole step (on another core) for a ~4.5 ms frog factorization; the
    /// swinging frog's A changes so fast that a factor 4 steps old already needs 60+ iterations.
    int pickup_setups = 2;
    /// Factorize in a BackgroundWork thread (waited for at pick-up and in the destructor): the core starts a thread
    /// only when asked (docs/DESIGN.md, "Overview"). false: at pick-up, in the caller's thread (same results).
    bool background_refactor = false;
    /// Turn the factor with the rows' rotations since it was made: P^-1 = Q (L L^T)^-1 Q^T with Q
    /// the block-diagonal turn of each row's frame (ShiftedSystem::block_frames), since
    /// K_now = Q K_then Q^T for a part that turned rigidly. Pays for a body that swings (the
    /// tail-held frog: 2.3 -> 1.3 ms per step), costs where parts vibrate after a cut (the cut
    /// frog: 28 -> 41 iterations per step); docs/BENCHMARKS.md, issue 12.
    bool follow_rotations = false;
    /// When K's pattern or size changed (a cut), factorize the new A at once in the step; false: the
    /// old factor on the old rows and Jacobi on the new ones until a refresh lands. Measured on test
    /// 5's cuts (docs/BENCHMARKS.md, issue 12): a cut step then costs one factorization instead of up
    /// to max_iterations iterations with a factor that no longer fits (worst 18 -> 11 ms, median
    /// during the cuts 3.0 -> 1.7 ms).
    bool refactor_on_growth = true;

    /// The one range rule of these settings: "" when refresh_iterations >= 0 and pickup_setups >= 1,
    /// else what is wrong (each caller throws it as its own error type).
    [[nodiscard]] std::string problem() const;
  };
  /// What the solver did, for benchmarks and tests. All but `pickups_waited` are deterministic.
  struct Counters {
    long setups = 0;
    long factorizations = 0;        ///< synchronous ones (first setup, unusable factor)
    long refreshes_started = 0;
    long refreshes_picked_up = 0;   ///< installed factors
    long refresh_failures = 0;      ///< refreshes that could not be factorized (old factor kept)
    long refreshes_discarded = 0;   ///< in flight when a synchronous factorization replaced the factor
    long pickups_waited = 0;        ///< pick-ups that had to wait for the worker (timing-dependent)
    long iterations = 0;            ///< CG iterations of all solves
    long factor_rows = 0;           ///< rows the factor in use covers (the rest: Jacobi)
  };

  CholeskyPcgSolver(PcgSolver::Settings pcg, Refresh refresh);
  /// Waits for a refresh in flight.
  ~CholeskyPcgSolver() override;
  CholeskyPcgSolver(const CholeskyPcgSolver&) = delete;
  CholeskyPcgSolver& operator=(const CholeskyPcgSolver&) = delete;
  using LinearSolver::solve;
  void setup(const ShiftedSystem& system) override;
  SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] bool is_set_up() const override;
  [[nodiscard]] std::string_view name() const override { return "pcgCholesky"; }
  void lend_work_team(WorkTeam* team) override;
  /// Refresh::follow_rotations.
  [[nodiscard]] bool follows_block_frames() const override;
  /// As PcgSolver::record_residuals.
  void record_residuals(std::vector<double>* history);
  /// The next setup factorizes at once (the refresh in flight is discarded).
  void forget_earlier_setups() override;

  [[nodiscard]] const Counters& counters() const;
  /// Why the last refresh failed ("" if none did).
  [[nodiscard]] const std::string& last_refresh_failure() const;
  /// Symbolic analyses so far, over both factors (the one in use and the one being refreshed).
  [[nodiscard]] int symbolic_analysis_count() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

/// Sparse Cholesky (SuiteSparse CHOLMOD; simplicial unless the factor is dense, cholmod_factor.cpp). The symbolic analysis (ordering, pattern of L)
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
  /// Keeps the factor when it is of the same K's pattern and size (else setup()): the solves that
  /// follow run CG on A preconditioned by it, turned with the rows' rotations since it was made
  /// (turned_factor.hpp; the block frames of both systems), to NEARBY_TOLERANCE, and factorize A
  /// after all if CG has not got there in NEARBY_ITERATIONS. A Newton correction then costs a few
  /// back-substitutions instead of a factorization (docs/DESIGN.md, "A correction's solve keeps the
  /// step's factor"). solve_roughly() stops CG at NEARBY_FORCING_TERM (an inexact Newton step: the
  /// co-rotational tangent leaves the corrections converging linearly, 2-3x a correction, far above
  /// that); refine() carries a converged correction on to NEARBY_TOLERANCE. After
  /// CG, each part's translation is corrected (PartTranslations): the momentum balance an exact
  /// solve gives a free part holds whatever CG's stop. Reports CG's residual.
  void setup_nearby(const ShiftedSystem& system) override;
  /// x = A^-1 b with the factor; reports the true relative residual (one product with A).
  SolveReport solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  SolveReport solve_roughly(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  SolveReport refine(const Eigen::VectorXd& b, Eigen::VectorXd& x) override;
  [[nodiscard]] bool solves_roughly() const override { return true; }
  void lend_work_team(WorkTeam* team) override;
  static constexpr double NEARBY_TOLERANCE = 1e-6;
  static constexpr double NEARBY_FORCING_TERM = 1e-2;
  static constexpr int NEARBY_ITERATIONS = 40;
  [[nodiscard]] bool is_set_up() const override;
  [[nodiscard]] std::string_view name() const override { return "cholmod"; }
  /// The rows' frames turn the step's factor for a Newton correction's solves (setup_nearby).
  [[nodiscard]] bool follows_block_frames() const override { return true; }

  /// How many symbolic analyses were done so far (tests check it is reused).
  [[nodiscard]] int symbolic_analysis_count() const;

 private:
  SolveReport solve_nearby(const Eigen::VectorXd& b, Eigen::VectorXd& x, double tolerance);
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace tissue
