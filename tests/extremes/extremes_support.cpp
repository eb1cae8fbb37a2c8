// The extremes suite's runner, scenes and table (see extremes_support.hpp).
#include "extremes_support.hpp"

#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>

namespace tissue::extremes {
namespace {

// Vertex v's 3 entries of a position vector (3 per vertex).
Eigen::Vector3d vertex_of(const Eigen::VectorXd& positions_m, int v) {
  return positions_m.segment<3>(3 * static_cast<Eigen::Index>(v));
}

}  // namespace

std::string_view method_label(Method method) {
  switch (method) {
    case Method::euler_pcg:
      return "BE + PCG (1e-3, 10 it.)";
    case Method::euler_cholmod:
      return "BE + CHOLMOD";
    case Method::ida_klu:
      return "IDA + KLU";
    case Method::ida_krylov:
      return "IDA + GMRES";
  }
  return "?";
}

std::string_view method_id(Method method) {
  switch (method) {
    case Method::euler_pcg:
      return "EulerPcg";
    case Method::euler_cholmod:
      return "EulerCholmod";
    case Method::ida_klu:
      return "IdaKlu";
    case Method::ida_krylov:
      return "IdaKrylov";
  }
  return "Unknown";
}

int ida_max_internal_steps() {
  const char* value = std::getenv("TISSUE_EXTREMES_IDA_MAX_INTERNAL_STEPS");
  return value != nullptr && std::atoi(value) > 0 ? std::atoi(value) : IDA_MAX_INTERNAL_STEPS;
}

void use_method(TissueSettings& settings, Method method) {
  switch (method) {
    case Method::euler_pcg:
      settings.integrator.kind = IntegratorKind::backward_euler;
      settings.solver.kind = LinearSolverKind::pcg;
      settings.solver.pcg = PcgSolver::Settings{1e-3, 10};
      break;
    case Method::euler_cholmod:
      settings.integrator.kind = IntegratorKind::backward_euler;
      settings.solver.kind = LinearSolverKind::cholmod;
      break;
    case Method::ida_klu:
      settings.integrator.kind = IntegratorKind::ida;
      settings.integrator.ida.linear_solver = IdaLinearSolverKind::klu;
      settings.integrator.ida.max_internal_steps = ida_max_internal_steps();
      break;
    case Method::ida_krylov:
      settings.integrator.kind = IntegratorKind::ida;
      settings.integrator.ida.linear_solver = IdaLinearSolverKind::krylov;
      settings.integrator.ida.max_internal_steps = ida_max_internal_steps();
      break;
  }
}

int step_threads() {
  const char* value = std::getenv("TISSUE_EXTREMES_THREADS");
  return value != nullptr && std::atoi(value) > 0 ? std::atoi(value) : 1;
}

TissueSettings default_settings() {
  TissueSettings settings;
  settings.integrator.threads = step_threads();
  settings.body.material = Material{1.0e5, 0.4, 1000.0};
  settings.body.damping = RayleighDamping{1.0, 1e-3};
  settings.body.gravity_m_per_s2 = {0.0, 0.0, -9.81};
  settings.step_size_s = 1e-3;
  settings.integrator.newton.linearize_at_predicted_end = true;  // the products' step
  return settings;
}

Scene cantilever_beam() {
  Scene scene{make_box_mesh(10, 2, 2, 0.01), default_settings()};
  scene.settings.body.fixed_vertices = vertices_at_minimum(scene.mesh, 0, 0.0);
  scene.settings.interaction.blade_length_m = 0.06;
  return scene;
}

Scene pad() {
  Scene scene{make_box_mesh(6, 4, 2, 0.01), default_settings()};
  scene.settings.body.fixed_vertices = vertices_at_minimum(scene.mesh, 2, 0.0);
  return scene;
}

int phase_steps(int release_steps) { return UNDER_SANITIZER ? std::max(1, release_steps / 4) : release_steps; }

Scene frog_on_tray() {
  Scene scene{read_veg(std::string(TISSUE_MESH_DIR) + "/frog.veg"), default_settings()};
  scene.settings.body.fixed_vertices = vertices_at_minimum(scene.mesh, 2, 0.25);
  return scene;
}

Eigen::Vector3d top_surface_point(const Tissue& tissue, double x_m, double y_m) {
  const Eigen::VectorXd& x = tissue.current_positions_m();
  double top = -1e300;
  for (Eigen::Index k = 2; k < x.size(); k += 3) top = std::max(top, x(k));
  const Eigen::Vector3d above(x_m, y_m, top + 0.1);
  const Eigen::Vector3d below(x_m, y_m, top - 1.0);
  std::vector<SurfaceBvh::SegmentHit> hits;
  tissue.surface_bvh().intersect_segment(above, below, x, hits);
  if (hits.empty()) return {x_m, y_m, top};
  double first = 1.0;
  for (const SurfaceBvh::SegmentHit& hit : hits) first = std::min(first, hit.segment_parameter);
  return above + first * (below - above);
}

bool move_tool(Run& run, const Eigen::Vector3d& to, double speed_m_per_s, ToolMode mode,
               const Eigen::Quaterniond& orientation) {
  const Eigen::Vector3d from = run.tissue().tool().tip_position_m;
  const double per_step_m = speed_m_per_s * run.tissue().settings().step_size_s;
  const int count = std::max(1, static_cast<int>(std::ceil((to - from).norm() / per_step_m - 1e-9)));
  for (int k = 1; k <= count && run.running(); ++k) {
    run.step_with(ToolPose{from + (to - from) * (static_cast<double>(k) / count), orientation, mode});
  }
  return run.running();
}

int inverted_tet_count(const Tissue& tissue) {
  const TetMesh& mesh = tissue.body().mesh();
  const Eigen::VectorXd& x = tissue.current_positions_m();
  int count = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    if (tissue.body().cut_tet_index(t) >= 0) continue;  // its real vertices may pass each other: the parts separate
    const Tet& tet = mesh.tets[static_cast<size_t>(t)];
    const Eigen::Vector3d a = vertex_of(x, tet[0]);
    const Eigen::Matrix3d edges =
        (Eigen::Matrix3d() << vertex_of(x, tet[1]) - a, vertex_of(x, tet[2]) - a, vertex_of(x, tet[3]) - a).finished();
    if (edges.determinant() < 0.0) ++count;
  }
  return count;
}

bool inside_body(const Tissue& tissue, const Eigen::VectorXd& positions_m, const Eigen::Vector3d& point_m) {
  // A ray off the mesh's grid directions (so that it does not run along edges of a box mesh),
  // against every surface triangle (Moeller-Trumbore).
  const Eigen::Vector3d direction = Eigen::Vector3d(0.123, 0.0456, 1.0).normalized();
  int crossings = 0;
  for (const std::array<int, 3>& triangle : tissue.surface().triangles) {
    const Eigen::Vector3d a = vertex_of(positions_m, triangle[0]);
    const Eigen::Vector3d ab = vertex_of(positions_m, triangle[1]) - a;
    const Eigen::Vector3d ac = vertex_of(positions_m, triangle[2]) - a;
    const Eigen::Vector3d p = direction.cross(ac);
    const double det = ab.dot(p);
    if (std::abs(det) < 1e-300) continue;
    const Eigen::Vector3d t = point_m - a;
    const double u = t.dot(p) / det;
    const Eigen::Vector3d q = t.cross(ab);
    const double v = direction.dot(q) / det;
    const double distance = ac.dot(q) / det;
    if (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && distance > 0.0) ++crossings;
  }
  return crossings % 2 == 1;
}

double smallest_volume_fraction(const Tissue& tissue) {
  double smallest = 0.5;
  for (const CutTet& cut : tissue.body().cut_tets())
    smallest = std::min({smallest, cut.weight_above, cut.weight_below});
  return smallest;
}

bool verbose() {
  const char* value = std::getenv("TISSUE_EXTREMES_VERBOSE");
  return value != nullptr && *value != '\0' && *value != '0';
}

double hang_limit_s() { return UNDER_SANITIZER ? 600.0 : 60.0; }
// A bound on a case's wall time that tells a runaway from a slow case, not a speed target: the
// slowest case (StripHundredCuts with IDA + KLU, IDA restarting at each of ~100 cuts) took 10.0-10.3 s
// for 284-290 of its 350 steps on a shared 2-core VM (2026-11-25, at c9c431d), so 10 s failed it there.
double case_budget_s() { return UNDER_SANITIZER ? 100.0 : 30.0; }

// Aborts the process if the case is still running after hang_limit_s(): a hang must not pass as a
// slow test, and ctest's own timeout would not name the case.
struct Run::Watchdog {
  std::mutex mutex;
  std::condition_variable done_signal;
  bool done = false;
  std::thread thread;

  Watchdog(std::string name, double limit_s) {
    thread = std::thread([this, name = std::move(name), limit_s] {
      std::unique_lock lock(mutex);
      const auto limit = std::chrono::duration<double>(limit_s);
      if (!done_signal.wait_for(lock, limit, [this] { return done; })) {
        std::fprintf(stderr, "extremes: case %s still running after %.0f s: counted as a hang, aborting\n",
                     name.c_str(), limit_s);
        std::fflush(stderr);
        std::abort();
      }
    });
  }
  ~Watchdog() {
    {
      const std::lock_guard lock(mutex);
      done = true;
    }
    done_signal.notify_all();
    thread.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;
};

Run::Run(std::string name, Method method, Scene scene, double time_scale)
    : m_name(std::move(name)),
      m_method(method),
      m_budget_s(case_budget_s() * time_scale),
      m_start(std::chrono::steady_clock::now()) {
  m_watchdog = std::make_unique<Watchdog>(m_name, hang_limit_s() * time_scale);
  use_method(scene.settings, method);
  try {
    m_tissue = std::make_unique<Tissue>(std::move(scene.mesh), std::move(scene.settings));
  } catch (const ParameterError& error) {
    m_outcome.kind = Outcome::Kind::refused_setup;
    m_outcome.reason = std::string("ParameterError: ") + error.what();
    m_running = false;
  } catch (const std::exception& error) {
    m_outcome.kind = Outcome::Kind::failed;
    m_outcome.reason = std::string("set-up threw something other than a ParameterError: ") + error.what();
    m_running = false;
  }
}

Run::~Run() = default;

void Run::fail(const std::string& why) {
  if (m_outcome.kind == Outcome::Kind::failed) return;  // keep the first failure
  m_outcome.kind = Outcome::Kind::failed;
  m_outcome.reason = why + " (at step " + std::to_string(m_outcome.steps) + ")";
  m_running = false;
}

void Run::set_tool(const ToolPose& pose) {
  if (!m_running) return;
  try {
    m_tissue->set_tool(pose);
  } catch (const std::exception& error) {
    fail(std::string("the script's tool pose was refused: ") + error.what());
  }
}

bool Run::steps(int count) {
  for (int k = 0; k < count && m_running; ++k) step();
  return m_running;
}

bool Run::step() {
  if (!m_running) return false;
  Tissue& tissue = *m_tissue;
  const double time_before = tissue.time_s();
  m_positions_before = tissue.current_positions_m();
  m_displacement_before = tissue.state().displacement_m;
  m_velocity_before = tissue.state().velocity_m_per_s;
  TissueStepReport report;
  const auto step_start = std::chrono::steady_clock::now();
  try {
    report = tissue.step();
  } catch (const IntegrationError& error) {
    // A refusal: it must say why and leave the time (and the dynamic state) as it was.
    m_running = false;
    const DynamicState& state = tissue.state();
    std::string problem;
    if (std::string_view(error.what()).empty()) problem += " with an empty message";
    if (tissue.time_s() != time_before) problem += "; the time advanced";
    if (!state.displacement_m.allFinite() || !state.velocity_m_per_s.allFinite())
      problem += "; the state is not finite";
    // A cut in the refused step may have grown the state (new enriched unknowns start at zero).
    const Eigen::Index n = m_displacement_before.size();
    if (state.displacement_m.size() < n || state.displacement_m.head(n) != m_displacement_before ||
        state.velocity_m_per_s.head(n) != m_velocity_before ||
        !state.displacement_m.tail(state.displacement_m.size() - n).isZero(0.0)) {
      problem += "; the state changed";
    }
    if (problem.empty()) {
      m_outcome.kind = Outcome::Kind::refused_step;
      m_outcome.reason = error.what();
      m_outcome.reason +=
          " (step " + std::to_string(m_outcome.steps + 1) + ", t = " + std::to_string(time_before) + " s)";
    } else {
      fail(std::string("IntegrationError ") + error.what() + " but" + problem);
    }
    return false;
  } catch (const std::exception& error) {
    fail(std::string("step() threw something other than an IntegrationError: ") + error.what());
    return false;
  }
  ++m_outcome.steps;
  m_outcome.max_internal_steps = std::max(m_outcome.max_internal_steps, report.dynamics.internal_steps);
  m_outcome.cut_tets = tissue.body().cut_tet_count();
  m_outcome.touched = m_outcome.touched || tissue.contact().active;
  m_outcome.max_inverted_tets = std::max(m_outcome.max_inverted_tets, inverted_tet_count(tissue));
  // The Tissue holds the tool it applies to the hand's top speed (tip and blade end).
  const ToolPose& applied = tissue.applied_tool();
  if (applied.mode == m_applied_before.mode && applied.mode != ToolMode::none) {
    const InteractionSettings& interaction = tissue.settings().interaction;
    const Eigen::Vector3d axis = applied.orientation * Eigen::Vector3d::UnitZ();
    const Eigen::Vector3d axis_before = m_applied_before.orientation * Eigen::Vector3d::UnitZ();
    const double move_m = std::max((applied.tip_position_m - m_applied_before.tip_position_m).norm(),
                                   (applied.tip_position_m + interaction.blade_length_m * axis -
                                    m_applied_before.tip_position_m - interaction.blade_length_m * axis_before)
                                       .norm());
    const double limit_m = interaction.max_tool_speed_m_per_s * tissue.settings().step_size_s;
    if (move_m > limit_m * (1.0 + 1e-9) + 1e-12) {
      fail("the applied tool moved " + std::to_string(move_m) + " m in one step, the limit is " +
           std::to_string(limit_m) + " m");
      return false;
    }
  }
  m_applied_before = applied;
  // The god-object: a contact starts only where the tip went into the body (PointContact::update),
  // so at its first step the tip is inside; a probe inside the body without a contact has slipped
  // through the surface.
  if (applied.mode == ToolMode::probe && tissue.settings().interaction.contact_enabled &&
      tissue.body().cut_tets().empty()) {
    // Where the contact was decided: the positions at the start of the step. Not a failure: the
    // god-object holds a tool pushed through a thin part at the side it entered (point_contact.hpp),
    // which only the tool's speed limit bounds; the table notes it.
    if (tissue.contact().active && !m_contact_before && m_outcome.contact_started_outside_at == 0 &&
        !inside_body(tissue, m_positions_before, applied.tip_position_m)) {
      m_outcome.contact_started_outside_at = m_outcome.steps;
    }
    if (!tissue.contact().active && inside_body(tissue, tissue.current_positions_m(), applied.tip_position_m)) {
      ++m_outcome.probe_inside_free_steps;
    }
  }
  m_contact_before = tissue.contact().active;
  const DynamicState& state = tissue.state();
  if (!state.displacement_m.allFinite() || !state.velocity_m_per_s.allFinite() ||
      !tissue.current_positions_m().allFinite() || !std::isfinite(tissue.time_s())) {
    fail("the state is not finite and the step did not refuse");
    return false;
  }
  // The contact spring's work on the body in this step (file comment of the header): the fall of its
  // potential, the spring fixed within the step.
  if (tissue.contact_spring().spring()) {
    m_tool_work_j += tissue.contact_spring().energy_j(m_positions_before) -
                     tissue.contact_spring().energy_j(tissue.current_positions_m());
  }
  record_energy();
  if (verbose()) {
    std::printf(
        "[extremes] %s step %d t %.6g: T+V %.6g J, bound %.6g J (tool %.6g J), internal steps %d, newton %d, "
        "linear %ld, unknowns %d, cut tets %zu, contact %d, %.3g ms (step %.3g: assembly %.3g, solve %.3g, guard "
        "%.3g, cut %.3g, enrich %.3g, contact %.3g, positions %.3g)\n",
        m_name.c_str(), m_outcome.steps, tissue.time_s(), m_last_energy_j, m_last_bound_j, m_tool_work_j,
        report.dynamics.internal_steps, report.dynamics.newton_iterations, report.dynamics.linear_iterations,
        tissue.body().dof_count(), static_cast<size_t>(tissue.body().cut_tet_count()), tissue.contact().active ? 1 : 0,
        1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - step_start).count(),
        1e3 * report.total_s, 1e3 * report.dynamics.assembly_s, 1e3 * report.dynamics.solve_s,
        1e3 * report.dynamics.guard_s, 1e3 * report.cut_s, 1e3 * report.enrich_s, 1e3 * report.contact_s,
        1e3 * report.positions_s);
  }
  if (m_running && std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count() > m_budget_s) {
    fail("took longer than the budget of " + std::to_string(m_budget_s) + " s");
  }
  return m_running;
}

void Run::record_energy() {
  Tissue& tissue = *m_tissue;
  const double energy_j = tissue.kinetic_energy_j() + tissue.elastic_energy_j();
  const double gravity_work_j = tissue.body().external_force_n().dot(tissue.state().displacement_m);
  const double bound_j = gravity_work_j + m_tool_work_j;
  m_last_energy_j = energy_j;
  m_last_bound_j = bound_j;
  m_outcome.max_energy_j = std::max(m_outcome.max_energy_j, energy_j);
  m_outcome.max_bound_j = std::max(m_outcome.max_bound_j, bound_j);
  const Eigen::VectorXd& u = tissue.state().displacement_m;
  for (Eigen::Index k = 0; k + 2 < u.size(); k += 3) {
    m_outcome.max_displacement_m = std::max(m_outcome.max_displacement_m, u.segment<3>(k).norm());
  }
  if (!std::isfinite(energy_j)) {
    fail("the energy is not finite");
    return;
  }
  const double excess_j = energy_j - bound_j;
  if (m_outcome.max_bound_j > 0.0) {
    m_outcome.worst_excess = std::max(m_outcome.worst_excess, excess_j / m_outcome.max_bound_j);
  }
  if (excess_j > 0.05 * m_outcome.max_bound_j + 1e-12) {
    char text[200];
    std::snprintf(text, sizeof text, "energy %.4g J above the work put in, %.4g J (largest so far %.4g J)", energy_j,
                  bound_j, m_outcome.max_bound_j);
    // The run goes on (the table shows how far the energy goes); the first failure is kept.
    if (m_outcome.kind != Outcome::Kind::failed) {
      m_outcome.kind = Outcome::Kind::failed;
      m_outcome.reason = std::string(text) + " at step " + std::to_string(m_outcome.steps);
    }
  }
}

Outcome Run::finish() {
  m_outcome.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
  m_outcome.budget_s = m_budget_s;
  m_running = false;
  return m_outcome;
}

namespace {

struct Table {
  std::vector<std::string> rows;
  std::map<std::string, std::array<std::string, ALL_METHODS.size()>> cells;
};

Table& table() {
  static Table instance;
  return instance;
}

size_t column(Method method) {
  return static_cast<size_t>(std::find(ALL_METHODS.begin(), ALL_METHODS.end(), method) - ALL_METHODS.begin());
}

std::string short_number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2g", value);
  return text;
}

std::string cell_of(const Outcome& outcome) {
  std::ostringstream text;
  switch (outcome.kind) {
    case Outcome::Kind::ok:
      text << "ok (" << short_number(outcome.max_energy_j) << " / " << short_number(outcome.max_bound_j) << " J, "
           << outcome.steps << " steps, " << short_number(outcome.wall_s) << " s)";
      if (outcome.contact_started_outside_at > 0) {
        text << "; a contact began with the tip through the body, outside it (step "
             << outcome.contact_started_outside_at << ")";
      }

      break;
    case Outcome::Kind::refused_setup:
    case Outcome::Kind::refused_step:
      text << "refused: " << outcome.reason << "; " << short_number(outcome.wall_s) << " s";
      break;
    case Outcome::Kind::failed:
      text << "**FAILED**: " << outcome.reason << "; max " << short_number(outcome.max_energy_j) << " / "
           << short_number(outcome.max_bound_j) << " J over " << outcome.steps << " steps, "
           << short_number(outcome.wall_s) << " s";
      break;
  }
  std::string cell = text.str();
  std::replace(cell.begin(), cell.end(), '|', '/');
  std::replace(cell.begin(), cell.end(), '\n', ' ');
  return cell;
}

// Prints the table after the last test when TISSUE_EXTREMES_TABLE is set: "1" (or "-") to standard
// output, anything else is a file to write it to.
class TablePrinter : public ::testing::Environment {
 public:
  void TearDown() override {
    const char* where = std::getenv("TISSUE_EXTREMES_TABLE");
    if (where == nullptr || *where == '\0') return;
    const std::string text = markdown_table();
    const std::string target(where);
    if (target == "1" || target == "-") {
      std::printf("\n%s", text.c_str());
    } else {
      std::ofstream(target) << text;
    }
  }
};

[[maybe_unused]] ::testing::Environment* const registered_table_printer =
    ::testing::AddGlobalTestEnvironment(new TablePrinter);

}  // namespace

void record_cell(const std::string& row, Method method, const std::string& cell) {
  Table& t = table();
  if (!t.cells.contains(row)) t.rows.push_back(row);
  t.cells[row][column(method)] = cell;
}

std::string markdown_table() {
  const Table& t = table();
  std::ostringstream text;
  text << "| case |";
  for (const Method method : ALL_METHODS) text << ' ' << method_label(method) << " |";
  text << "\n|---|";
  for (size_t k = 0; k < ALL_METHODS.size(); ++k) text << "---|";
  text << '\n';
  for (const std::string& row : t.rows) {
    text << "| " << row << " |";
    for (const std::string& cell : t.cells.at(row)) text << ' ' << (cell.empty() ? "not run" : cell) << " |";
    text << '\n';
  }
  return text.str();
}

void run_case(const Case& c, Method method) {
  if (std::find(c.not_run.begin(), c.not_run.end(), method) != c.not_run.end()) {
    record_cell(c.label, method, "not run: " + c.not_run_reason);
    GTEST_SKIP() << "not run with " << method_label(method) << ": " << c.not_run_reason;
  }
  Outcome outcome;
  {
    Run run(c.id + "/" + std::string(method_id(method)), method, c.scene(), c.time_scale);
    if (run.running()) c.script(run);
    outcome = run.finish();
  }
  std::printf(
      "[extremes] %s, %s: %s [most internal steps in a step %d, cut tets %d%s, probe inside without contact %d "
      "steps, inverted tets up to %d, largest |u| %.3g m]\n",
      c.id.c_str(), std::string(method_label(method)).c_str(), cell_of(outcome).c_str(), outcome.max_internal_steps,
      outcome.cut_tets, outcome.touched ? ", touched" : "", outcome.probe_inside_free_steps, outcome.max_inverted_tets,
      outcome.max_displacement_m);
  record_cell(c.label, method, cell_of(outcome));
  if (std::find(c.known_failures.begin(), c.known_failures.end(), method) != c.known_failures.end()) {
    EXPECT_EQ(outcome.kind, Outcome::Kind::failed)
        << "the open finding no longer reproduces: take it off known_failures (" << c.known_failure_note << ")";
    if (outcome.kind == Outcome::Kind::failed) {
      GTEST_SKIP() << "open finding, not fixed (docs/BENCHMARKS.md): " << c.known_failure_note << "; "
                   << outcome.reason;
    }
    return;
  }
  EXPECT_NE(outcome.kind, Outcome::Kind::failed) << outcome.reason;
  const bool refused = outcome.kind == Outcome::Kind::refused_setup || outcome.kind == Outcome::Kind::refused_step;
  if (refused) {
    const bool allowed = std::find(c.may_refuse.begin(), c.may_refuse.end(), method) != c.may_refuse.end();
    EXPECT_TRUE(allowed) << "refused where a bounded state was expected: " << outcome.reason;
    if (allowed) std::printf("[extremes]   a refusal this case allows: %s\n", c.refusal_note.c_str());
  }
  EXPECT_LT(outcome.wall_s, outcome.budget_s);
}

std::string case_test_name(const std::vector<Case>& cases, int index, Method method) {
  return cases[static_cast<size_t>(index)].id + "_" + std::string(method_id(method));
}

}  // namespace tissue::extremes
