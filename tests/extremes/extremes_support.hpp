// The stability-at-the-extremes suite (issue 10, point 4): what every case shares. A case is a
// scene (mesh and settings) and a script that drives the Tissue step by step; it is run once per
// integrator (Method), and must end either with a bounded, finite state or with a clear refusal:
// a ParameterError when the Tissue is built, or an IntegrationError from step() whose message says
// why, with the time not advanced and the state unchanged. Never NaN, a hang or a crash.
//
// "Bounded" is an energy balance. With D = alpha M + beta K >= 0 the equations of motion give
//   d/dt (T + V) = v^T f_ext + (the contact spring's power on the body) - v^T D v,
// so T(t) + V(t) <= B(t), the work put in: f_ext^T u(t) for the constant gravity (u(0) = 0; a
// new enriched unknown starts at a = 0, so a cut should leave the sum as it is), plus, for the
// probe, the work of its spring on the body. The spring's end (the tool tip) is fixed within a step, so
// the spring is conservative there and its work in step k is exact whatever path the body takes:
//   W_k = E_k(x_p(t_{k-1})) - E_k(x_p(t_k)),   E_k = PointSpringTerm::energy_j (k/2 |D (x_p - tip_k)|^2 - F . x_p),
// x_p the spring's material point. Backward Euler's numerical damping and the solvers' errors
// only lower T + V; IDA's error control allows a drift of order of its tolerance: a case passes
// when T + V <= B + 5% of the largest B so far + 1e-12 J at every step. The scalpel puts no work
// in: a cut should not change T + V, its parts starting on the tet (docs/BENCHMARKS.md, issue 10,
// shows where they do not).
#pragma once

#include "core/integrate/integrator.hpp"
#include "core/tissue.hpp"
#include "support/under_sanitizer.hpp"

#include <Eigen/Core>
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

namespace tissue::extremes {

/// True in the sanitizer builds (CI's asan preset): cases shrink there, never silently.
using test::UNDER_SANITIZER;

/// The integrators every case runs with.
enum class Method { euler_pcg, euler_cholmod, ida_klu, ida_krylov };
inline constexpr std::array<Method, 4> ALL_METHODS{Method::euler_pcg, Method::euler_cholmod, Method::ida_klu,
                                                   Method::ida_krylov};

/// IDA's runaway guard in this suite: IdaSettings::max_internal_steps lowered from its default
/// 20000 to 2000 internal steps per step(). A crawl (internal steps of microseconds) is refused
/// the same way, but in 0.3-2 s instead of 3-8 s or more on these 200-2100 unknown bodies
/// (docs/BENCHMARKS.md); the cases that end bounded need at most ~1400 (the 1 GPa beam, GMRES).
inline constexpr int IDA_MAX_INTERNAL_STEPS = 2000;
/// The step's threads (IntegratorSettings::threads): 1, or TISSUE_EXTREMES_THREADS when set (> 0;
/// the settings' check refuses more than MAX_STEP_THREADS), to time the cases on a team.
int step_threads();
/// IDA_MAX_INTERNAL_STEPS, or TISSUE_EXTREMES_IDA_MAX_INTERNAL_STEPS when set (> 0): 20000 runs
/// IDA at its default guard (docs/BENCHMARKS.md measures what that costs).
int ida_max_internal_steps();

/// Column title in the table.
std::string_view method_label(Method method);
/// For test names (letters only).
std::string_view method_id(Method method);
/// Backward Euler + PCG at the real-time setting (tolerance 1e-3, 10 iterations), backward Euler +
/// CHOLMOD, IDA with KLU or GMRES at IDA's defaults but for its runaway guard (above).
void use_method(TissueSettings& settings, Method method);

struct Scene {
  TetMesh mesh;
  TissueSettings settings;
};

/// The FMU's default material and damping (E = 100 kPa, nu = 0.4, rho = 1000 kg/m^3; alpha = 1/s,
/// beta = 1 ms), gravity -z, steps of 1 ms.
TissueSettings default_settings();
/// A cantilever of 10 x 2 x 2 cubes of 1 cm (0.1 x 0.02 x 0.02 m, 297 unknowns), clamped at x = 0.
Scene cantilever_beam();
/// A pad of 6 x 4 x 2 cubes of 1 cm (0.06 x 0.04 x 0.02 m, 210 unknowns) held at its bottom (z = 0).
Scene pad();
inline constexpr double PAD_TOP_M = 0.02;
/// A point of the pad's top off the mesh's 1 cm grid of vertices (tools aim here).
inline constexpr double PAD_X_M = 0.0313, PAD_Y_M = 0.0207;
/// The frog (meshes/frog.veg, 817 vertices, 2450 tets) as the Tissue FMU sets it up: held by its
/// lowest 25% in z, gravity -z.
Scene frog_on_tray();

/// Steps of a case's hold or free phase: as given in the release build, a quarter (at least 1)
/// under sanitizers, where everything runs ~10 times slower. The scripted tool motions are kept.
int phase_steps(int release_steps);

/// Outward-facing surface point where the vertical line at (x, y) first meets the body from above
/// (the current positions); the bounding box's top if it misses.
Eigen::Vector3d top_surface_point(const Tissue& tissue, double x_m, double y_m);

/// Where a case ended.
struct Outcome {
  enum class Kind { ok, refused_setup, refused_step, failed };
  Kind kind = Kind::ok;
  std::string reason;         ///< the refusal's message, or what failed
  int steps = 0;              ///< steps completed
  double max_energy_j = 0.0;  ///< max over the steps of T + V
  double max_bound_j = 0.0;   ///< max over the steps of B (see the file comment)
  double worst_excess = 0.0;  ///< max over the steps of (T + V - B) / max B so far (<= 0.05 passes)
  double max_displacement_m = 0.0;
  int max_internal_steps = 0;       ///< the most internal steps one step() took (IDA's error control)
  int cut_tets = 0;                 ///< at the end
  int max_inverted_tets = 0;        ///< the most tets (uncut, at the vertex positions) inverted after a step
  bool touched = false;             ///< the probe was in contact at some step
  int probe_inside_free_steps = 0;  ///< steps the probe's tip ended inside the body without a contact
  /// The first step whose new contact began with the tip outside the body (its path went through
  /// it: the god-object holds the tool at the side it entered); 0 if none.
  int contact_started_outside_at = 0;
  double wall_s = 0.0;
  double budget_s = 0.0;  ///< the wall time it was given (case_budget_s() times Case::time_scale)
};

/// Runs one case: builds the Tissue (a ParameterError is a refusal), steps it through the script,
/// checks every step (finite state, energy balance) and turns a refusal into the Outcome. Also a
/// watchdog: a case still running after hang_limit_s() aborts the executable with its name.
class Run {
 public:
  /// `time_scale`: the case may take this many times the suite's budget and hang limit (Case::time_scale).
  Run(std::string name, Method method, Scene scene, double time_scale = 1.0);
  ~Run();
  Run(const Run&) = delete;
  Run& operator=(const Run&) = delete;

  /// False once the case has ended (refused or failed): scripts stop then.
  [[nodiscard]] bool running() const { return m_running; }
  /// One Tissue step with its checks; false when the case ended.
  bool step();
  /// `count` steps; false when the case ended.
  bool steps(int count);
  /// Sets the tool (a ParameterError here ends the case as a failure: scripts give valid poses).
  void set_tool(const ToolPose& pose);
  /// The tool to `pose`, then one step.
  bool step_with(const ToolPose& pose) {
    set_tool(pose);
    return step();
  }
  [[nodiscard]] Tissue& tissue() { return *m_tissue; }
  [[nodiscard]] const std::string& name() const { return m_name; }
  /// Ends the case as a failure (a script's own check).
  void fail(const std::string& why);
  [[nodiscard]] Outcome finish();
  /// The outcome so far (scripts check what their case must have produced).
  [[nodiscard]] const Outcome& outcome() const { return m_outcome; }

 private:
  void record_energy();

  std::string m_name;
  Method m_method;
  std::unique_ptr<Tissue> m_tissue;
  double m_budget_s;
  Outcome m_outcome;
  bool m_running = true;
  double m_tool_work_j = 0.0;
  double m_last_energy_j = 0.0, m_last_bound_j = 0.0;
  ToolPose m_applied_before;
  bool m_contact_before = false;
  std::chrono::steady_clock::time_point m_start;
  struct Watchdog;
  std::unique_ptr<Watchdog> m_watchdog;
  Eigen::VectorXd m_positions_before, m_displacement_before, m_velocity_before;
};

/// Moves the tool's target in a straight line from the pose set last to `to` at `speed_m_per_s`
/// (one target per step, the last exactly at `to`), stepping once per target. The Tissue holds
/// the tool it applies to its own speed limit. False when the case ended.
bool move_tool(Run& run, const Eigen::Vector3d& to, double speed_m_per_s, ToolMode mode,
               const Eigen::Quaterniond& orientation = Eigen::Quaterniond::Identity());

/// Tets of the mesh whose vertices (current positions) have a negative volume.
int inverted_tet_count(const Tissue& tissue);
/// Whether a point is inside the body at `positions_m` (3 per vertex): the parity of the mesh
/// surface's triangles (cut faces left out) a ray from it crosses.
bool inside_body(const Tissue& tissue, const Eigen::VectorXd& positions_m, const Eigen::Vector3d& point_m);
/// The smallest min(w_a, w_b) over the cut tets; 0.5 without cuts.
double smallest_volume_fraction(const Tissue& tissue);

/// TISSUE_EXTREMES_VERBOSE=1: every step prints its energy, bound and the integrator's counts.
bool verbose();

/// Wall time after which a case counts as hung (the watchdog aborts): 60 s, 10 x under sanitizers.
double hang_limit_s();
/// What a case may take and still count as "finishing in seconds": 10 s, 10 x under sanitizers.
double case_budget_s();

/// One row of the table: a scene and a script, run once per method.
struct Case {
  std::string id;     ///< for the test name (letters and digits)
  std::string label;  ///< the table's row title (markdown)
  std::function<Scene()> scene;
  std::function<void(Run&)> script;
  /// The methods that may refuse this case (IntegrationError or ParameterError), with why that is
  /// the right outcome; any other refusal fails the test.
  std::vector<Method> may_refuse = {};
  std::string refusal_note = {};
  /// Methods this case is not run with, and why (too slow for the suite's time; measured once and
  /// reported in docs/BENCHMARKS.md). The test is reported as skipped with the reason, and the
  /// table cell says "not run: <reason>".
  std::vector<Method> not_run = {};
  std::string not_run_reason = {};
  /// Open findings: methods with which this case is known to fail (an energy above the work put
  /// in), not fixed yet, with what causes it. The case still runs and its cell says FAILED; the test
  /// is reported as skipped with the finding while it fails, and fails once it no longer does (so
  /// that a fix takes the finding off this list).
  std::vector<Method> known_failures = {};
  std::string known_failure_note = {};
  /// The case may take this many times the suite's budget and hang limit (case_budget_s(),
  /// hang_limit_s()): a case long by design, its time measured in docs/BENCHMARKS.md.
  double time_scale = 1.0;
};

/// Runs `c` with `method`, checks the outcome with gtest assertions and records the table cell.
void run_case(const Case& c, Method method);

/// Records a table cell (run_case does it; the bad-input cases record their own).
void record_cell(const std::string& row, Method method, const std::string& cell);

/// The markdown table of every cell recorded so far (rows in the order first recorded).
std::string markdown_table();

/// gtest parameter names: "<case id>_<method id>".
std::string case_test_name(const std::vector<Case>& cases, int index, Method method);

}  // namespace tissue::extremes

/// One parameterized suite `Extremes/<suite>.EndsBoundedOrRefused/<case id>_<method id>` over the
/// cases `cases_function()` returns and every method, each test a run_case(). Use inside
/// namespace tissue::extremes.
#define TISSUE_EXTREMES_SUITE(suite, cases_function)                                                         \
  class suite : public ::testing::TestWithParam<std::tuple<int, Method>> {};                                   \
  TEST_P(suite, EndsBoundedOrRefused) {                                                                        \
    run_case(cases_function()[static_cast<size_t>(std::get<0>(GetParam()))], std::get<1>(GetParam()));        \
  }                                                                                                            \
  INSTANTIATE_TEST_SUITE_P(Extremes, suite,                                                                    \
                           ::testing::Combine(::testing::Range(0, static_cast<int>(cases_function().size())), \
                                              ::testing::ValuesIn(ALL_METHODS)),                               \
                           [](const auto& param_info) {                                                        \
                             return case_test_name(cases_function(), std::get<0>(param_info.param),            \
                                                   std::get<1>(param_info.param));                             \
                           })
