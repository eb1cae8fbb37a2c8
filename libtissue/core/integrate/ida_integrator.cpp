// IdaIntegrator (see ida_integrator.hpp).
#include "core/integrate/ida_integrator.hpp"

#include "core/wall_clock.hpp"

#include <ida/ida.h>
#include <ida/ida_ls.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunlinsol/sunlinsol_spgmr.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace tissue {
namespace {

// GMRES: Krylov subspace size before a restart, and restarts allowed.
constexpr int KRYLOV_DIMENSION = 30;
constexpr int KRYLOV_RESTARTS = 2;

}  // namespace

IdaLinearSolverKind parse_ida_linear_solver_kind(std::string_view name) { return IDA_LINEAR_SOLVER_NAMES.parse(name); }

std::string_view to_string(IdaLinearSolverKind kind) { return IDA_LINEAR_SOLVER_NAMES.name(kind); }

void validate(const IdaSettings& settings) {
  const auto positive = [](double value, const char* what) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      throw ParameterError(std::string("IDA ") + what + " must be finite and > 0, got " + std::to_string(value));
    }
  };
  positive(settings.relative_tolerance, "relative tolerance");
  positive(settings.absolute_tolerance, "absolute tolerance");
  if (settings.max_order < 1 || settings.max_order > 5) {
    throw ParameterError("IDA maximum order must be 1..5, got " + std::to_string(settings.max_order));
  }
  if (!(settings.max_step_s >= 0.0) || !std::isfinite(settings.max_step_s)) {
    throw ParameterError("IDA maximum step must be finite and >= 0 s (0: no limit), got " +
                         std::to_string(settings.max_step_s));
  }
  if (settings.max_internal_steps < 1) {
    throw ParameterError("IDA internal step limit must be >= 1, got " + std::to_string(settings.max_internal_steps));
  }
  if (settings.linear_solver != IdaLinearSolverKind::klu && settings.linear_solver != IdaLinearSolverKind::krylov) {
    throw ParameterError("unknown IDA linear solver kind");
  }
}

struct IdaIntegrator::Impl {
  IdaSettings settings;
  SUNContext context = nullptr;
  void* ida = nullptr;
  N_Vector y = nullptr;   // [u; v]
  N_Vector yp = nullptr;  // [u'; v']
  SUNMatrix jacobian = nullptr;
  SUNLinearSolver linear_solver = nullptr;
  long unknowns = -1;  // n (y has 2n)
  bool restart_pending = true;
  double last_cj = 0.0;  // c_j of the last internal step, 0 before the first
  int creations = 0;
  int reinitializations = 0;
  std::string last_error;

  // The model during step() (the callbacks' user data is this Impl).
  DynamicsModel* model = nullptr;
  Eigen::VectorXd internal_force_n, stiffness_times_velocity, product;
  Eigen::VectorXd tangent_at_u;  // the u the model's tangent was last evaluated at
  bool tangent_current = false;

  // KLU: the compressed-column pattern of J and where each entry's K value is.
  const BlockSparseMatrix* pattern_source = nullptr;
  std::uint64_t pattern_revision = 0, layout_revision = 0;
  std::vector<sunindextype> column_start, row_index;
  std::vector<int> stiffness_value;  // per entry: index into K's values, -1 for the identity entries
  std::vector<sunindextype> v_diagonal_entry;  // per v column j: the position of J(n + j, n + j)

  // Krylov: the inverse diagonal of the Schur complement S.
  Eigen::VectorXd inverse_schur_diagonal;
  Eigen::VectorXd stiffness_diagonal;

  explicit Impl(IdaSettings s) : settings(s) {
    if (SUNContext_Create(nullptr, &context) != 0) throw IntegrationError("IDA: cannot create a SUNDIALS context");
  }
  ~Impl() {
    free_memory();
    SUNContext_Free(&context);
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void free_memory() {
    if (ida != nullptr) IDAFree(&ida);
    if (linear_solver != nullptr) SUNLinSolFree(linear_solver);
    if (jacobian != nullptr) SUNMatDestroy(jacobian);
    if (y != nullptr) N_VDestroy(y);
    if (yp != nullptr) N_VDestroy(yp);
    ida = nullptr;
    linear_solver = nullptr;
    jacobian = nullptr;
    y = yp = nullptr;
    unknowns = -1;
    pattern_source = nullptr;
  }

  static Impl& of(void* user_data) { return *static_cast<Impl*>(user_data); }
  [[nodiscard]] long n() const { return unknowns; }
  static Eigen::Map<Eigen::VectorXd> map(N_Vector vector, long offset, long length) {
    return {N_VGetArrayPointer(vector) + offset, length};
  }

  // f_int(u) and K(u); the tangent is re-evaluated only when u differs from the last one.
  void evaluate(const Eigen::Map<Eigen::VectorXd>& u) {
    if (tangent_current && tangent_at_u.size() == u.size() &&
        std::memcmp(tangent_at_u.data(), u.data(), sizeof(double) * static_cast<size_t>(u.size())) == 0) {
      return;
    }
    tangent_at_u = u;
    model->evaluate(tangent_at_u, internal_force_n, /*update_tangent=*/true);
    tangent_current = true;
  }

  // F2 = M v' + alpha M v + beta K v + f_int(u) - f_ext into `out` (length n).
  void dynamic_residual(const Eigen::Map<Eigen::VectorXd>& u, const Eigen::Map<Eigen::VectorXd>& v,
                        const Eigen::Map<Eigen::VectorXd>& v_dot, Eigen::Map<Eigen::VectorXd>& out) {
    evaluate(u);
    stiffness_times_velocity.resize(n());
    model->tangent().multiply(v, stiffness_times_velocity);
    out = model->mass_kg().cwiseProduct(v_dot) + model->mass_damping_kg_per_s().cwiseProduct(v) +
          model->stiffness_damping_s() * stiffness_times_velocity + internal_force_n - model->external_force_n();
  }

  static int residual(realtype /*t*/, N_Vector yy, N_Vector yyp, N_Vector rr, void* user_data) {
    Impl& self = of(user_data);
    const long n = self.n();
    try {
      const auto u = map(yy, 0, n);
      const auto v = map(yy, n, n);
      const auto u_dot = map(yyp, 0, n);
      const auto v_dot = map(yyp, n, n);
      auto r_kinematic = map(rr, 0, n);
      auto r_dynamic = map(rr, n, n);
      if (!u.allFinite() || !v.allFinite()) return 1;  // recoverable: IDA retries with a smaller step
      r_kinematic = u_dot - v;
      self.dynamic_residual(u, v, v_dot, r_dynamic);
      return r_dynamic.allFinite() ? 0 : 1;
    } catch (const std::exception& error) {
      self.last_error = error.what();
      return -1;
    }
  }

  // The compressed-column pattern of J: column j < n (u_j): row j (c_j), rows n + i for K(i, j);
  // column n + j (v_j): row j (-1), rows n + i for beta K(i, j) (+ (alpha + c_j) m_j on the diagonal).
  // K is symmetric and stored by block rows, so column j of K is read from block row j / 3.
  void build_pattern(const BlockSparseMatrix& stiffness) {
    const long count = n();
    column_start.assign(static_cast<size_t>(2 * count) + 1, 0);
    row_index.clear();
    stiffness_value.clear();
    v_diagonal_entry.assign(static_cast<size_t>(count), -1);
    std::vector<std::pair<int, int>> column;  // (row i of K, value index of K(j, i))
    std::vector<std::vector<std::pair<int, int>>> columns(static_cast<size_t>(count));
    for (int block_row = 0; block_row < stiffness.block_rows(); ++block_row) {
      const int begin = stiffness.row_begin(block_row);
      for (int a = 0; a < 3; ++a) {
        column.clear();
        for (int slot = begin; slot < begin + stiffness.row_size(block_row); ++slot) {
          const int block_col = stiffness.slot_column(slot);
          for (int b = 0; b < 3; ++b) column.emplace_back(3 * block_col + b, 9 * slot + a + 3 * b);
        }
        std::sort(column.begin(), column.end());
        columns[static_cast<size_t>(3 * block_row + a)] = column;
      }
    }
    for (int half = 0; half < 2; ++half) {
      for (long j = 0; j < count; ++j) {
        const long col = half * count + j;
        row_index.push_back(j);  // c_j I (u columns) or -I (v columns)
        stiffness_value.push_back(-1);
        for (const auto& [i, value] : columns[static_cast<size_t>(j)]) {
          if (half == 1 && i == j) v_diagonal_entry[static_cast<size_t>(j)] = static_cast<sunindextype>(row_index.size());
          row_index.push_back(count + i);
          stiffness_value.push_back(value);
        }
        column_start[static_cast<size_t>(col) + 1] = static_cast<sunindextype>(row_index.size());
      }
    }
    pattern_source = &stiffness;
    pattern_revision = stiffness.pattern_revision();
    layout_revision = stiffness.layout_revision();
  }

  [[nodiscard]] bool pattern_current(const BlockSparseMatrix& stiffness) const {
    return pattern_source == &stiffness && pattern_revision == stiffness.pattern_revision() &&
           layout_revision == stiffness.layout_revision() && stiffness.rows() == n();
  }

  static int jacobian_fn(realtype /*t*/, realtype c_j, N_Vector yy, N_Vector /*yp*/, N_Vector /*r*/, SUNMatrix matrix,
                         void* user_data, N_Vector /*tmp1*/, N_Vector /*tmp2*/, N_Vector /*tmp3*/) {
    Impl& self = of(user_data);
    const long count = self.n();
    try {
      self.evaluate(map(yy, 0, count));
      const BlockSparseMatrix& stiffness = self.model->tangent();
      if (!self.pattern_current(stiffness)) return -1;  // the size changed under IDA: a restart was missed
      const auto entries = static_cast<sunindextype>(self.row_index.size());
      if (SUNSparseMatrix_NNZ(matrix) < entries) return -1;
      std::copy(self.column_start.begin(), self.column_start.end(), SUNSparseMatrix_IndexPointers(matrix));
      std::copy(self.row_index.begin(), self.row_index.end(), SUNSparseMatrix_IndexValues(matrix));
      realtype* data = SUNSparseMatrix_Data(matrix);
      const double* k = stiffness.block(0).data();
      const double beta_s = self.model->stiffness_damping_s();
      const Eigen::VectorXd& mass = self.model->mass_kg();
      const Eigen::VectorXd& mass_damping = self.model->mass_damping_kg_per_s();
      const auto first_v_entry = self.column_start[static_cast<size_t>(count)];
      for (sunindextype e = 0; e < entries; ++e) {
        const int value = self.stiffness_value[static_cast<size_t>(e)];
        const bool u_column = e < first_v_entry;
        if (value < 0) {
          data[e] = u_column ? c_j : -1.0;
        } else {
          data[e] = u_column ? k[value] : beta_s * k[value];
        }
      }
      for (long j = 0; j < count; ++j) {
        data[self.v_diagonal_entry[static_cast<size_t>(j)]] += mass_damping[j] + c_j * mass[j];
      }
      self.last_cj = c_j;
      return 0;
    } catch (const std::exception& error) {
      self.last_error = error.what();
      return -1;
    }
  }

  // J v for GMRES: [c_j v_u - v_v;  K v_u + (alpha + c_j) M v_v + beta K v_v].
  static int jacobian_times(realtype /*t*/, N_Vector yy, N_Vector /*yp*/, N_Vector /*rr*/, N_Vector vector,
                            N_Vector result, realtype c_j, void* user_data, N_Vector /*tmp1*/, N_Vector /*tmp2*/) {
    Impl& self = of(user_data);
    const long count = self.n();
    try {
      self.evaluate(map(yy, 0, count));
      const auto x_u = map(vector, 0, count);
      const auto x_v = map(vector, count, count);
      auto out_u = map(result, 0, count);
      auto out_v = map(result, count, count);
      out_u = c_j * x_u - x_v;
      self.product.resize(count);
      self.model->tangent().multiply(x_u + self.model->stiffness_damping_s() * x_v, self.product);
      out_v = self.product + (self.model->mass_damping_kg_per_s() + c_j * self.model->mass_kg()).cwiseProduct(x_v);
      return 0;
    } catch (const std::exception& error) {
      self.last_error = error.what();
      return -1;
    }
  }

  // The preconditioner: eliminate v exactly, S by its diagonal.
  static int preconditioner_setup(realtype /*t*/, N_Vector yy, N_Vector /*yp*/, N_Vector /*rr*/, realtype c_j,
                                  void* user_data) {
    Impl& self = of(user_data);
    const long count = self.n();
    try {
      self.evaluate(map(yy, 0, count));
      Eigen::VectorXd shift;
      const ShiftedSystem schur = newton_stiffness_system(*self.model, c_j, shift);
      schur.stiffness->diagonal(self.stiffness_diagonal);
      self.inverse_schur_diagonal = (schur.stiffness_scale * self.stiffness_diagonal + shift).cwiseInverse();
      self.last_cj = c_j;
      return self.inverse_schur_diagonal.allFinite() && (self.inverse_schur_diagonal.array() > 0.0).all() ? 0 : 1;
    } catch (const std::exception& error) {
      self.last_error = error.what();
      return -1;
    }
  }

  // z = P^-1 r: du = diag(S)^-1 (r_v + ((alpha + c_j) M + beta K) r_u), dv = c_j du - r_u.
  static int preconditioner_solve(realtype /*t*/, N_Vector /*yy*/, N_Vector /*yp*/, N_Vector /*rr*/, N_Vector rvec,
                                  N_Vector zvec, realtype c_j, realtype /*delta*/, void* user_data) {
    Impl& self = of(user_data);
    const long count = self.n();
    const auto r_u = map(rvec, 0, count);
    const auto r_v = map(rvec, count, count);
    auto z_u = map(zvec, 0, count);
    auto z_v = map(zvec, count, count);
    self.product.resize(count);
    self.model->tangent().multiply(r_u, self.product);
    z_u = self.inverse_schur_diagonal.cwiseProduct(
        r_v + (self.model->mass_damping_kg_per_s() + c_j * self.model->mass_kg()).cwiseProduct(r_u) +
        self.model->stiffness_damping_s() * self.product);
    z_v = c_j * z_u - r_u;
    return 0;
  }

  static void error_handler(int /*code*/, const char* /*module*/, const char* function, char* message,
                            void* user_data) {
    of(user_data).last_error = std::string(function) + ": " + message;
  }

  void check(int flag, const char* what) {
    if (flag < 0) throw IntegrationError(std::string("IDA: ") + what + " failed (flag " + std::to_string(flag) + ")");
  }

  // The consistent y' at a state: u' = v, v' = M^-1 (f_ext - f_int(u) - D v).
  void consistent_derivative(const DynamicState& state) {
    const long count = n();
    map(y, 0, count) = state.displacement_m;
    map(y, count, count) = state.velocity_m_per_s;
    const auto u = map(y, 0, count);
    const auto v = map(y, count, count);
    Eigen::VectorXd zero = Eigen::VectorXd::Zero(count);
    auto v_dot = map(yp, count, count);
    const Eigen::Map<Eigen::VectorXd> zero_map(zero.data(), count);
    dynamic_residual(u, v, zero_map, v_dot);  // M * 0 + D v + f_int - f_ext
    v_dot = -v_dot.cwiseQuotient(model->mass_kg());
    map(yp, 0, count) = state.velocity_m_per_s;
    if (!v_dot.allFinite()) throw IntegrationError("IDA: the initial acceleration is not finite; state kept");
  }

  void create(const DynamicState& state) {
    free_memory();
    const long count = model->dof_count();
    unknowns = count;
    y = N_VNew_Serial(2 * count, context);
    yp = N_VNew_Serial(2 * count, context);
    if (y == nullptr || yp == nullptr) throw IntegrationError("IDA: cannot allocate the state vectors");
    tangent_current = false;
    consistent_derivative(state);
    ida = IDACreate(context);
    if (ida == nullptr) throw IntegrationError("IDA: IDACreate failed");
    check(IDASetErrHandlerFn(ida, error_handler, this), "IDASetErrHandlerFn");
    check(IDAInit(ida, residual, state.time_s, y, yp), "IDAInit");
    check(IDASetUserData(ida, this), "IDASetUserData");
    check(IDASStolerances(ida, settings.relative_tolerance, settings.absolute_tolerance), "IDASStolerances");
    check(IDASetMaxOrd(ida, settings.max_order), "IDASetMaxOrd");
    if (settings.max_step_s > 0.0) check(IDASetMaxStep(ida, settings.max_step_s), "IDASetMaxStep");
    check(IDASetMaxNumSteps(ida, settings.max_internal_steps), "IDASetMaxNumSteps");
    if (settings.linear_solver == IdaLinearSolverKind::klu) {
      build_pattern(model->tangent());
      jacobian = SUNSparseMatrix(2 * count, 2 * count, static_cast<sunindextype>(row_index.size()), CSC_MAT, context);
      if (jacobian == nullptr) throw IntegrationError("IDA: cannot allocate the sparse Jacobian");
      linear_solver = SUNLinSol_KLU(y, jacobian, context);
      if (linear_solver == nullptr) throw IntegrationError("IDA: cannot create the KLU solver");
      check(IDASetLinearSolver(ida, linear_solver, jacobian), "IDASetLinearSolver");
      check(IDASetJacFn(ida, jacobian_fn), "IDASetJacFn");
    } else {
      linear_solver = SUNLinSol_SPGMR(y, SUN_PREC_LEFT, KRYLOV_DIMENSION, context);
      if (linear_solver == nullptr) throw IntegrationError("IDA: cannot create the GMRES solver");
      check(SUNLinSol_SPGMRSetMaxRestarts(linear_solver, KRYLOV_RESTARTS), "SUNLinSol_SPGMRSetMaxRestarts");
      check(IDASetLinearSolver(ida, linear_solver, nullptr), "IDASetLinearSolver");
      check(IDASetPreconditioner(ida, preconditioner_setup, preconditioner_solve), "IDASetPreconditioner");
      check(IDASetJacTimes(ida, nullptr, jacobian_times), "IDASetJacTimes");
    }
    ++creations;
    last_cj = 0.0;
  }

  void reinitialize(const DynamicState& state) {
    tangent_current = false;
    consistent_derivative(state);
    check(IDAReInit(ida, state.time_s, y, yp), "IDAReInit");
    ++reinitializations;
    last_cj = 0.0;
  }

  // Whether IDA's y is this state (IDA continues) or someone changed it (IDA restarts).
  [[nodiscard]] bool holds(const DynamicState& state) const {
    const long count = n();
    const double* values = N_VGetArrayPointer(y);
    const auto bytes = sizeof(double) * static_cast<size_t>(count);
    return std::memcmp(values, state.displacement_m.data(), bytes) == 0 &&
           std::memcmp(values + count, state.velocity_m_per_s.data(), bytes) == 0;
  }
};

IdaIntegrator::IdaIntegrator(IdaSettings settings) : m_settings(settings) {
  validate(m_settings);
  m_impl = std::make_unique<Impl>(m_settings);
}

IdaIntegrator::~IdaIntegrator() = default;

int IdaIntegrator::creations() const { return m_impl->creations; }
int IdaIntegrator::reinitializations() const { return m_impl->reinitializations; }

void IdaIntegrator::restore_internal_state(const Eigen::VectorXd& internal_state) {
  if (internal_state.size() != 0) {
    throw std::invalid_argument("IDA has no internal state to restore (got " + std::to_string(internal_state.size()) +
                                " values)");
  }
  restart(Restart::state_restored);
}

void IdaIntegrator::restart(Restart why) {
  if (why == Restart::state_saved) return;  // the history continues; a restore restarts it
  Impl& impl = *m_impl;
  impl.restart_pending = true;
  if (why == Restart::system_grown) impl.free_memory();
}

ShiftedSystem IdaIntegrator::newton_stiffness(const DynamicsModel& model, double step_size_s,
                                              Eigen::VectorXd& diagonal) const {
  if (!(step_size_s > 0.0) || !std::isfinite(step_size_s)) {
    throw ParameterError("Newton matrix: step size must be finite and > 0 s, got " + std::to_string(step_size_s));
  }
  const double c = m_impl->last_cj > 0.0 ? m_impl->last_cj : 1.0 / step_size_s;
  return newton_stiffness_system(model, c, diagonal);
}

StepReport IdaIntegrator::step(DynamicsModel& model, DynamicState& state, double step_size_s) {
  if (!(step_size_s > 0.0) || !std::isfinite(step_size_s)) {
    throw IntegrationError("step size must be finite and > 0 s, got " + std::to_string(step_size_s));
  }
  const long n = model.dof_count();
  if (state.displacement_m.size() != n || state.velocity_m_per_s.size() != n) {
    throw IntegrationError("state has " + std::to_string(state.displacement_m.size()) + " unknowns, model has " +
                           std::to_string(n));
  }
  Impl& impl = *m_impl;
  impl.model = &model;
  impl.last_error.clear();
  const auto start = std::chrono::steady_clock::now();
  StepReport report;
  try {
    const bool same_system = impl.ida != nullptr && impl.n() == n &&
                             (m_settings.linear_solver != IdaLinearSolverKind::klu || impl.pattern_current(model.tangent()));
    if (!same_system) {
      impl.create(state);
    } else if (impl.restart_pending || !impl.holds(state)) {
      impl.reinitialize(state);
    }
    impl.restart_pending = false;
    long steps_before = 0, newton_before = 0, linear_before = 0;
    IDAGetNumSteps(impl.ida, &steps_before);
    IDAGetNumNonlinSolvIters(impl.ida, &newton_before);
    IDAGetNumLinIters(impl.ida, &linear_before);
    double reached_s = state.time_s;
    const double end_s = state.time_s + step_size_s;
    impl.check(IDASetStopTime(impl.ida, end_s), "IDASetStopTime");
    const int flag = IDASolve(impl.ida, end_s, &reached_s, impl.y, impl.yp, IDA_NORMAL);
    if (flag == IDA_TOO_MUCH_WORK) {
      throw IntegrationError("IDA: more than " + std::to_string(m_settings.max_internal_steps) +
                             " internal steps (IdaSettings::max_internal_steps) before t = " + std::to_string(end_s) +
                             " s, at t = " + std::to_string(reached_s) + " s; state kept");
    }
    if (flag < 0) {
      throw IntegrationError("IDA: the step failed (flag " + std::to_string(flag) + "): " + impl.last_error +
                             "; state kept");
    }
    const auto u = Impl::map(impl.y, 0, n);
    const auto v = Impl::map(impl.y, n, n);
    if (!u.allFinite() || !v.allFinite()) throw IntegrationError("IDA: the state is not finite; state kept");
    long steps = 0, newton = 0, linear = 0;
    IDAGetNumSteps(impl.ida, &steps);
    IDAGetNumNonlinSolvIters(impl.ida, &newton);
    IDAGetNumLinIters(impl.ida, &linear);
    double cj = 0.0;
    if (IDAGetCurrentCj(impl.ida, &cj) == IDA_SUCCESS && cj > 0.0 && std::isfinite(cj)) impl.last_cj = cj;
    report.internal_steps = static_cast<int>(steps - steps_before);
    report.newton_iterations = static_cast<int>(newton - newton_before);
    report.linear_iterations = linear - linear_before;
    report.solve.iterations = static_cast<int>(report.linear_iterations);
    report.solve.converged = true;
    state.displacement_m = u;
    state.velocity_m_per_s = v;
    state.time_s = end_s;
  } catch (const IntegrationError&) {
    impl.restart_pending = true;
    impl.model = nullptr;
    throw;
  } catch (const std::exception& error) {
    impl.restart_pending = true;
    impl.model = nullptr;
    throw IntegrationError(std::string("IDA: ") + error.what() + "; state kept");
  }
  impl.model = nullptr;
  report.solve_s = seconds_since(start);
  return report;
}

}  // namespace tissue
