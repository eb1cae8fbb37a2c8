// TwoLevelPcgSolver: CG (pcg_iteration.hpp) with the two-level preconditioner
// (two_level_preconditioner.hpp).
#include "core/solve/linear_solver.hpp"
#include "core/solve/pcg_iteration.hpp"
#include "core/solve/two_level_preconditioner.hpp"

namespace tissue {
namespace {
constexpr const char* TWO_LEVEL_PCG = "TwoLevelPcgSolver";
}  // namespace

TwoLevelPcgSolver::TwoLevelPcgSolver(PcgSolver::Settings settings)
    : m_settings(settings), m_preconditioner(std::make_unique<TwoLevelPreconditioner>()) {
  validate_pcg_settings(settings, TWO_LEVEL_PCG);
  m_work.matrix = HalfMatrix(resolved_precision(settings.matrix_precision, settings.tolerance));
}

TwoLevelPcgSolver::~TwoLevelPcgSolver() = default;

void TwoLevelPcgSolver::setup(const ShiftedSystem& system) { set_up(system, /*nearby=*/false); }

void TwoLevelPcgSolver::setup_nearby(const ShiftedSystem& system) { set_up(system, /*nearby=*/true); }

void TwoLevelPcgSolver::set_up(const ShiftedSystem& system, bool nearby) {
  m_system = ShiftedSystem{nullptr, 1.0, nullptr};
  system.check(TWO_LEVEL_PCG);
  if (system.block_positions != nullptr &&
      system.block_positions->size() < static_cast<size_t>(system.stiffness->block_rows())) {
    throw SolverError(std::string(TWO_LEVEL_PCG) + ": fewer block positions than block rows");
  }
  m_work.resize(system.rows());
  jacobi_inverse_diagonal(system, m_inverse_diagonal, TWO_LEVEL_PCG);  // also refuses a diagonal <= 0
  if (nearby) {
    m_preconditioner->setup_nearby(system, m_inverse_diagonal, m_team);
  } else {
    m_preconditioner->setup(system, m_inverse_diagonal, m_team);
  }
  m_work.matrix.assign(system, m_team);
  m_system = system;
}

bool TwoLevelPcgSolver::multiply_set_up(const ShiftedSystem& system, const Eigen::Ref<const Eigen::MatrixXd>& x,
                                        RowMajorMatrix& y) const {
  return multiply_set_up_copy(m_work, m_system, m_team, system, x, y);
}

SolveReport TwoLevelPcgSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  if (!is_set_up()) throw SolverError(std::string(TWO_LEVEL_PCG) + ": solve() without a setup()");
  m_system.check_sizes(b, x);
  return preconditioned_cg</*ROW_WISE=*/false>(
      m_system, b, x, m_settings.tolerance, m_settings.max_iterations, m_work, m_team,
      [this](const Eigen::VectorXd& r, Eigen::VectorXd& z, long, long) { m_preconditioner->apply(r, z, m_team); });
}

void TwoLevelPcgSolver::forget_earlier_setups() { m_preconditioner->forget(); }

int TwoLevelPcgSolver::aggregate_count() const { return m_preconditioner->aggregate_count(); }

int TwoLevelPcgSolver::coarse_size() const { return m_preconditioner->coarse_size(); }

}  // namespace tissue
