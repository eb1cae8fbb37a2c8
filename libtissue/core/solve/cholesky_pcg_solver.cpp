// CholeskyPcgSolver: CG preconditioned by a lagged CHOLMOD factor (rules in linear_solver.hpp).
//
// Why lagged and not refactorized: on the frog (2433 unknowns, 140k non-zeros in L) a numeric
// factorization takes ~4.5 ms, a solve with the factor ~0.07 ms. The factor of A_k is an excellent
// preconditioner of A_{k+j} for small j (co-rotation changes K gradually), so a few CG iterations
// replace a factorization, and the factorization moves to a worker thread.
//
// Determinism: the worker factorizes a copy of A's values (CholmodFactor::load, in the caller's
// thread) with its own cholmod_common, and the result is installed at a fixed setup count, never
// "when ready"; so every solve sees the same preconditioner in every run, with or without the thread.
// The worker (a BackgroundWork thread) shares nothing with the caller but the CholmodFactor it owns
// until the wait (plus an atomic flag that only feeds the timing counter `pickups_waited`).
#include "core/solve/cholmod_factor.hpp"
#include "core/solve/linear_solver.hpp"
#include "core/solve/pcg_iteration.hpp"
#include "core/solve/turned_factor.hpp"
#include "core/system/background_work.hpp"

#include <atomic>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace tissue {
namespace {

constexpr const char* CHOLESKY_PCG = "CholeskyPcgSolver";

}  // namespace

struct CholeskyPcgSolver::Impl {
  PcgSolver::Settings pcg;
  Refresh refresh;
  // Solves without BLAS: a refresh's factorization (BLAS) may run beside them (cholmod_factor.hpp).
  std::unique_ptr<CholmodFactor> active = std::make_unique<CholmodFactor>(CholmodFactor::Solves::without_blas);
  std::unique_ptr<CholmodFactor> spare = std::make_unique<CholmodFactor>(CholmodFactor::Solves::without_blas);
  BackgroundWork worker;                 // the refactorization beside the steps (refresh.background_refactor)
  std::atomic<bool> worker_done{false};  // its job has finished (a pick-up that had to wait is counted)
  bool in_flight = false;
  int setups_since_start = 0;
  bool refresh_wanted = false;  // the last solve asked for a new factor
  bool forgotten = false;       // forget_earlier_setups(): the factor is not used again

  ShiftedSystem system{nullptr, 1.0, nullptr};  // of the last setup()
  PcgWorkspace work;
  Eigen::VectorXd inverse_diagonal;  // 1 / diag(A): the rows the factor does not cover
  Counters counters;
  std::string last_failure;
  WorkTeam* team = nullptr;  // lent for a step: CG's products and updates (the factor solve stays on one thread)
  // The rows' frames when each factor's matrix was copied (empty: made without frames), and per
  // block row of the active factor the turn since then, Q = F_now F_then^T (empty: no turn).
  TurnedFactor turned;                        // the active factor's frames and turns (turned_factor.hpp)
  std::vector<Eigen::Matrix3d> spare_frames;  // the spare's, swapped in with it

  Impl(PcgSolver::Settings p, Refresh r) : pcg(p), refresh(r) { work.matrix = HalfMatrix(resolved_precision(p.matrix_precision, p.tolerance)); }
  ~Impl() { join(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void join() {
    if (!worker.pending()) return;
    if (!worker_done.load(std::memory_order_acquire)) ++counters.pickups_waited;
    worker.wait();
  }

  // The factor in use can precondition A (or its leading block): same matrix, not more rows.
  [[nodiscard]] bool usable(const BlockSparseMatrix& stiffness) const {
    return !forgotten && active->factored() && active->source() == &stiffness && active->rows() <= stiffness.rows();
  }
  [[nodiscard]] bool stale(const BlockSparseMatrix& stiffness) const {
    return active->pattern_revision() != stiffness.pattern_revision() || active->rows() != stiffness.rows();
  }

  void start_refresh(const ShiftedSystem& a) {
    spare->load(a);  // the snapshot: the used entries of A's upper triangle (the pattern only when new)
    copy_frames(a, spare_frames);
    ++counters.refreshes_started;
    in_flight = true;
    setups_since_start = 0;
    refresh_wanted = false;
    if (!refresh.background_refactor) return;
    worker_done.store(false, std::memory_order_relaxed);
    // Without a thread to be had, factorized here, now: the same result.
    worker.start([factor = spare.get(), done = &worker_done] {
      factor->factorize();  // noexcept: the status is read after the wait
      done->store(true, std::memory_order_release);
    });
  }

  // Installs the refresh started pickup_setups setups ago (factorizing it now without a worker).
  void pick_up(long rows) {
    if (worker.pending()) {
      join();
    } else if (!refresh.background_refactor) {
      spare->factorize();
    }
    in_flight = false;
    if (spare->factored() && spare->rows() <= rows) {
      std::swap(active, spare);
      std::swap(turned.frames, spare_frames);
      ++counters.refreshes_picked_up;
      refresh_wanted = false;  // the next solve says whether this factor does (after a failure: still wanted)
    } else {
      ++counters.refresh_failures;
      last_failure = spare->factored() ? std::string(CHOLESKY_PCG) + ": the refreshed factor has more rows than A"
                                       : spare->failure_message(CHOLESKY_PCG);
    }
  }

  void discard_refresh() {
    if (!in_flight) return;
    join();
    in_flight = false;
    ++counters.refreshes_discarded;
  }

  // The turn of each of the active factor's block rows since its matrix was copied; none unless
  // following rotations and both that copy and `a` have frames.
  void update_turns(const ShiftedSystem& a) {
    if (refresh.follow_rotations) {
      turned.update_turns(a, active->rows());
    } else {
      turned.turns.clear();
    }
  }

  // z = P^-1 r: the (turned) factor on its rows, Jacobi on the rows appended since.
  void precondition(const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    const long n = r.size();
    const long m = active->rows();
    turned.solve(*active, r, z);
    if (m < n) z.tail(n - m) = inverse_diagonal.tail(n - m).cwiseProduct(r.tail(n - m));
  }
};

std::string CholeskyPcgSolver::Refresh::problem() const {
  if (refresh_iterations < 0) return "pcgCholesky refresh iterations must be >= 0, got " + std::to_string(refresh_iterations);
  if (pickup_setups < 1) return "pcgCholesky pick-up setups must be >= 1, got " + std::to_string(pickup_setups);
  return "";
}

CholeskyPcgSolver::CholeskyPcgSolver(PcgSolver::Settings pcg, Refresh refresh) {
  validate_pcg_settings(pcg, CHOLESKY_PCG);
  if (const std::string problem = refresh.problem(); !problem.empty())
    throw SolverError(std::string(CHOLESKY_PCG) + ": " + problem);
  m_impl = std::make_unique<Impl>(pcg, refresh);
}

CholeskyPcgSolver::~CholeskyPcgSolver() = default;

void CholeskyPcgSolver::lend_work_team(WorkTeam* team) { m_impl->team = team; }

bool CholeskyPcgSolver::follows_block_frames() const { return m_impl->refresh.follow_rotations; }

void CholeskyPcgSolver::record_residuals(std::vector<double>* history) { m_impl->work.residual_history = history; }

bool CholeskyPcgSolver::is_set_up() const { return m_impl->system.stiffness != nullptr; }

const CholeskyPcgSolver::Counters& CholeskyPcgSolver::counters() const { return m_impl->counters; }

const std::string& CholeskyPcgSolver::last_refresh_failure() const { return m_impl->last_failure; }

int CholeskyPcgSolver::symbolic_analysis_count() const {
  // The spare's count is read only when no worker holds it.
  Impl& impl = *m_impl;
  return impl.active->analysis_count() + (impl.worker.pending() ? 0 : impl.spare->analysis_count());
}

void CholeskyPcgSolver::forget_earlier_setups() {
  Impl& impl = *m_impl;
  impl.discard_refresh();
  impl.forgotten = true;
  impl.refresh_wanted = false;
  impl.setups_since_start = 0;
}

void CholeskyPcgSolver::setup(const ShiftedSystem& system) {
  Impl& impl = *m_impl;
  impl.system = ShiftedSystem{nullptr, 1.0, nullptr};
  system.check(CHOLESKY_PCG);
  const long n = system.rows();
  ++impl.counters.setups;
  if (impl.in_flight && ++impl.setups_since_start >= impl.refresh.pickup_setups) impl.pick_up(n);

  jacobi_inverse_diagonal(system, impl.inverse_diagonal, CHOLESKY_PCG);  // also refuses a diagonal <= 0
  if (!impl.usable(*system.stiffness) || (impl.refresh.refactor_on_growth && impl.stale(*system.stiffness))) {
    impl.discard_refresh();  // older than what we factorize now
    impl.forgotten = false;
    impl.active->load(system);
    impl.turned.record_frames(system);
    ++impl.counters.factorizations;
    if (impl.active->factorize() != CholmodFactor::Status::ok) {
      impl.counters.factor_rows = 0;
      throw SolverError(impl.active->failure_message(CHOLESKY_PCG));
    }
  } else if (!impl.in_flight && (impl.refresh_wanted || impl.stale(*system.stiffness))) {
    impl.start_refresh(system);
  }
  impl.counters.factor_rows = impl.active->rows();
  impl.update_turns(system);
  impl.work.resize(n);
  impl.work.matrix.assign(system, impl.team);
  impl.system = system;
}

SolveReport CholeskyPcgSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Impl& impl = *m_impl;
  if (!is_set_up()) throw SolverError("CholeskyPcgSolver: solve() without a setup()");
  impl.system.check_sizes(b, x);
  const SolveReport report =
      preconditioned_cg</*ROW_WISE=*/false>(impl.system, b, x, impl.pcg.tolerance, impl.pcg.max_iterations, impl.work,
                                            impl.team, [&impl](const Eigen::VectorXd& r, Eigen::VectorXd& z, long, long) {
                                              impl.precondition(r, z);
                                            });
  impl.counters.iterations += report.iterations;
  if (!report.converged || report.iterations > impl.refresh.refresh_iterations) impl.refresh_wanted = true;
  return report;
}

}  // namespace tissue
