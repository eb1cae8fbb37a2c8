// tissue-host: drives the Tissue FMU next to the HapticLoop FMU (docs/DESIGN.md, "Host"), loading both
// through host/importer like any FMI importer would (it never links libtissue).
//   tissue-host run SCENARIO.toml [--offline] [--output DIR] [--record FILE.csv] ...
//   tissue-host info FILE.fmu
//   tissue-host bench [--steps N] ...
//   [mpirun -n N] tissue-host compare SCENARIO.toml [--settings FILE.toml] [--jobs N] [--output DIR] ...
#include "compare/compare.hpp"
#include "importer/fmu3.hpp"
#include "importer/fmu3_instance.hpp"
#include "importer/fmu_error.hpp"
#include "scenario/scenario.hpp"
#include "links/fmu_links.hpp"
#include "schedule/timer_check.hpp"
#include "session/session.hpp"
#include "view/live_view.hpp"

#include <CLI/CLI.hpp>

#ifdef TISSUE_HOST_MPI
#include "compare/mpi_distribution.hpp"
#endif

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <vector>

namespace {

using namespace tissue::host;

// This program's own folder (empty if the system does not say).
std::filesystem::path program_dir() {
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::filesystem::path() : exe.parent_path();
}

// Installed: <prefix>/bin/tissue-host -> <prefix>/share/tissue/<folder>; in the build tree:
// build/<preset>/host/tissue-host -> build/<preset>/<folder>, then `built` (where this build put it).
std::filesystem::path data_dir(const std::string& folder, const std::string& holds, const std::filesystem::path& built) {
  const std::filesystem::path here = program_dir();
  if (!here.empty()) {
    const std::filesystem::path installed = here / TISSUE_DATA_DIR_FROM_BIN / folder;
    if (std::filesystem::exists(installed / holds)) return installed.lexically_normal();
    const std::filesystem::path next_to_build = here.parent_path() / folder;
    if (std::filesystem::exists(next_to_build / holds)) return next_to_build;
  }
  return built;
}

std::filesystem::path default_fmu_dir() { return data_dir("fmus", "Tissue.fmu", TISSUE_DEFAULT_FMU_DIR); }

int run_command(const std::string& scenario_file, SessionOptions options, bool quiet, double duration_s) {
  Scenario scenario = load_scenario(scenario_file);
  if (duration_s > 0.0) scenario.duration_s = duration_s;
  if (!quiet) {
    std::cout << "tissue-host: " << scenario.name << " (" << scenario.duration_s << " s, "
              << (options.offline ? "offline" : "real time") << ")";
    if (!scenario.description.empty()) std::cout << ": " << scenario.description;
    std::cout << std::endl;
    options.progress = &std::cout;
  }
  const SessionSummary summary = run_session(scenario, options);
  print_summary(std::cout, summary, options.output_dir);
  if (!summary.realtime_priority && !options.offline && !quiet) {
    std::cout << "  note: " << summary.realtime_priority_note << "\n";
  }
  return summary.nan_detected || summary.tissue_errors > 0 || summary.haptic_errors > 0 ? 3 : 0;
}

int info_command(const std::string& fmu_file) {
  const Fmu3 fmu(fmu_file);
  const ModelDescription& d = fmu.description();
  std::cout << d.model_name() << " (FMI " << d.fmi_version() << ", binary reports " << fmu.version() << ")\n";
  if (!d.description().empty()) std::cout << "  " << d.description() << "\n";
  std::cout << "  instantiation token " << d.instantiation_token() << "\n";
  std::cout << "  co-simulation: get/set FMU state " << (d.co_simulation().can_get_and_set_fmu_state ? "yes" : "no")
            << ", serialize " << (d.co_simulation().can_serialize_fmu_state ? "yes" : "no") << "\n";
  std::cout << "  " << d.variables().size() << " variables:\n";
  for (const ModelVariable& v : d.variables()) {
    std::string shape;  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on operator+ chains
    for (const Dimension& dim : v.dimensions) {
      shape.append("[");
      if (!dim.start) shape.append("vr ");
      shape.append(std::to_string(dim.start ? *dim.start : dim.value_reference.value_or(0))).append("]");
    }
    std::cout << "    " << std::setw(4) << v.value_reference << "  " << std::left << std::setw(30) << (v.name + shape)
              << std::setw(12) << v.type << std::setw(20) << v.causality << std::setw(6) << v.unit
              << (v.start ? "start " + *v.start : std::string()) << std::right << "\n";
  }
  return 0;
}

int bench_command(const std::filesystem::path& fmu_dir, int steps, double tissue_step_s) {
  // The two FMUs' step costs through the importer, as the session calls them (offline, one thread).
  const Fmu3 tissue_fmu(fmu_dir / "Tissue.fmu");
  const Fmu3 haptic_fmu(fmu_dir / "HapticLoop.fmu");
  // As a scenario that does not set it: one internal step per communication step.
  TissueLink tissue(tissue_fmu, {ParameterSetting{"stepSize", tissue_step_s}});
  HapticLink haptic(haptic_fmu, {});
  std::vector<double> tissue_ms, haptic_us;
  ToolCommand away;
  away.position_m = {0.0, 0.0, 1.0};
  tissue.set_tool(away);
  for (int k = 0; k < steps; ++k) {
    const auto start = std::chrono::steady_clock::now();
    (void)tissue.step(k * tissue_step_s, tissue_step_s);
    tissue_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  DevicePose pose;
  HapticOutputs out;
  for (int n = 0; n < 10 * steps; ++n) {
    const auto start = std::chrono::steady_clock::now();
    haptic.set_device(pose);
    (void)haptic.step(n * 1e-3, 1e-3);
    haptic.read(out);
    haptic_us.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
  }
  const Percentiles tissue_cost = percentiles(tissue_ms, 1.0), haptic_cost = percentiles(haptic_us, 1.0);
  std::cout << "Tissue doStep (" << tissue_step_s * 1e3 << " ms, one internal step, tool away), " << steps
            << " steps: p50 " << tissue_cost.p50 << " ms, p99 " << tissue_cost.p99 << " ms\n";
  std::cout << "HapticLoop tick (set device, doStep 1 ms, get outputs), " << 10 * steps << " ticks: p50 "
            << haptic_cost.p50 << " us, p99 " << haptic_cost.p99 << " us\n";
  return 0;
}

// Under mpirun the ranks share the runs (MPI is initialized here only, never for `run`); rank 0
// prints and writes. An error on one rank ends them all rather than leave the others waiting.
int compare_command(CompareOptions options, bool quiet, int& argc, char**& argv) {
  if (!quiet) {
    options.progress = &std::cerr;
    options.progress_in_place = isatty(STDERR_FILENO) != 0;
  }
#ifdef TISSUE_HOST_MPI
  if (launched_by_mpi()) {
    MpiDistribution mpi(argc, argv);
    try {
      const CompareReport report = run_compare(options, mpi);
      if (mpi.rank() == 0) print_compare(std::cout, report, options.output_dir);
      return 0;
    } catch (const std::exception& error) {
      std::cerr << "tissue-host compare" << (mpi.rank() == 0 ? "" : " (rank " + std::to_string(mpi.rank()) + ")")
                << ": " << error.what() << std::endl;
      if (mpi.size() > 1) MpiDistribution::abort_all(2);
      return 2;
    }
  }
#endif
  (void)argc;
  (void)argv;
  SingleProcess one;
  const CompareReport report = run_compare(options, one);
  print_compare(std::cout, report, options.output_dir);
  return 0;
}

// Ctrl-C ends a real-time run early (its outputs written); a second one ends the process.
std::atomic<bool> g_stop_requested{false};
extern "C" void on_interrupt(int /*signal*/) {
  if (g_stop_requested.exchange(true)) std::_Exit(130);
}

// 128 random bits as hex: the access token of a view that listens beyond loopback.
std::string random_token() {
  std::random_device random;
  std::ostringstream out;
  for (int k = 0; k < 4; ++k) out << std::hex << std::setw(8) << std::setfill('0') << random();
  return out.str();
}

// `run`'s arguments, as the command line sets them.
struct RunArguments {
  std::string scenario_file;
  SessionOptions options;
  std::string output_dir = "session";
  std::string record_file;
  bool no_priority = false;
  bool view = false, mouse = false;
  int view_port = 8080;
  std::string view_listen = "127.0.0.1";
  double duration_s = 0.0;
};

// `compare`'s arguments, as the command line sets them.
struct CompareArguments {
  CompareOptions options;
  std::string scenario, settings_file;
  std::string output = "compare";
  double duration_s = 0.0;
};

// `fmu_dir` and `quiet` are shared with the other commands.
CLI::App* add_run_command(CLI::App& app, RunArguments& a, std::string& fmu_dir, bool& quiet) {
  CLI::App* run = app.add_subcommand("run", "Run a scenario (host/scenarios/*.toml) in real time or offline");
  run->add_option("scenario", a.scenario_file, "Scenario file (TOML)")->required()->check(CLI::ExistingFile);
  run->add_flag("--offline", a.options.offline, "Same schedule without sleeping; bitwise reproducible");
  run->add_option("--output,-o", a.output_dir, "Folder for summary.json, log.csv, frames, final.png")
      ->capture_default_str();
  run->add_option("--record", a.record_file, "Also write the device poses as a CSV a replay device plays back");
  run->add_option("--fmu-dir", fmu_dir, "Where Tissue.fmu and HapticLoop.fmu are (default: the build's fmus/)");
  run->add_flag("--no-rt-priority", a.no_priority, "Do not ask for SCHED_FIFO");
  run->add_flag("--quiet,-q", quiet, "Only the summary");
  run->add_flag("--view", a.view, "Serve a live 3D view of the session in the browser (http://127.0.0.1:PORT/)");
  run->add_option("--port", a.view_port, "The live view's port (0: any free port)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  run->add_option("--view-listen", a.view_listen,
                  "The address the view listens on; any but loopback needs the access token printed at start")
      ->capture_default_str();
  run->add_flag("--mouse", a.mouse, "The view's mouse and keyboard drive the tool (implies --view)");
  run->add_option("--duration", a.duration_s, "Run for this many seconds instead of the scenario's duration")
      ->check(CLI::PositiveNumber);
  return run;
}

CLI::App* add_bench_command(CLI::App& app, int& steps, double& step_s, std::string& fmu_dir) {
  CLI::App* bench = app.add_subcommand("bench", "Time the two FMUs' steps through the importer");
  bench->add_option("--steps", steps, "Tissue steps")->check(CLI::Range(1, 1000000))->capture_default_str();
  bench->add_option("--step", step_s, "Tissue communication step [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  bench->add_option("--fmu-dir", fmu_dir, "Where Tissue.fmu and HapticLoop.fmu are");
  return bench;
}

// `timer`'s arguments.
struct TimerArguments {
  double period_s = 1e-3;
  double duration_s = 10.0;
  std::string json_file;
  bool no_priority = false;
};

CLI::App* add_timer_command(CLI::App& app, TimerArguments& a) {
  CLI::App* timer = app.add_subcommand(
      "timer", "Check this machine's timer alone: the haptic thread's ticks with no work, its deadline misses");
  timer->add_option("--period", a.period_s, "Tick period [s]")->check(CLI::Range(1e-5, 1.0))->capture_default_str();
  timer->add_option("--duration", a.duration_s, "How long [s]")->check(CLI::Range(1e-3, 3600.0))->capture_default_str();
  timer->add_option("--json", a.json_file, "Also write the figures to this JSON file");
  timer->add_flag("--no-rt-priority", a.no_priority, "Do not ask for SCHED_FIFO");
  return timer;
}

int timer_command(const TimerArguments& a) {
  const TimerCheck check = check_timer(a.period_s, a.duration_s, !a.no_priority);
  print_timer_check(std::cout, check, a.period_s);
  if (!a.json_file.empty()) {
    std::ofstream json(a.json_file);
    json << check.to_json();
    if (!json) throw std::runtime_error("cannot write " + a.json_file);
  }
  return 0;
}

CLI::App* add_compare_command(CLI::App& app, CompareArguments& a, std::string& fmu_dir, bool& quiet) {
  CLI::App* compare =
      app.add_subcommand("compare",
                         "Run a scenario offline under several integrator settings against a reference: "
                         "compare.csv, compare.png, recommendation.txt (also under mpirun)");
  compare->add_option("scenario", a.scenario, "Scenario file (TOML)")->required()->check(CLI::ExistingFile);
  compare
      ->add_option("--settings", a.settings_file,
                   "TOML file with a [compare] table (default: the scenario's, else built-in)")
      ->check(CLI::ExistingFile);
  compare->add_option("--output,-o", a.output, "Folder for the outputs")->capture_default_str();
  compare->add_option("--jobs,-j", a.options.jobs, "Runs at once in this process (threads), >= 1")
      ->capture_default_str();
  compare->add_option("--steps", a.options.steps_s, "Internal steps [s] for every setting, e.g. 0.001,0.01")
      ->delimiter(',');
  compare->add_option("--duration", a.duration_s, "Run the scenario for DURATION seconds instead (e.g. shorter)");
  compare->add_option("--fmu-dir", fmu_dir, "Where Tissue.fmu and HapticLoop.fmu are");
  compare->add_flag("--quiet,-q", quiet, "No progress line");
  return compare;
}

// The live view's settings from `run`'s arguments; a token (printed) when it listens beyond loopback.
SessionOptions::View view_options(const RunArguments& a) {
  SessionOptions::View v;
  v.address = a.view_listen;
  v.port = static_cast<std::uint16_t>(a.view_port);
  v.static_dir = data_dir("view", "index.html", TISSUE_VIEW_DIR);
  if (!is_loopback_address(a.view_listen)) {
    v.token = random_token();
    std::cerr << "tissue-host: WARNING: the live view listens on " << a.view_listen
              << ", not on loopback: anyone who can reach it and has the token can watch";
    if (a.mouse) std::cerr << " and move the tool";
    std::cerr << ". Token: " << v.token << "\n";
  }
  return v;
}

// The session `run` asks for; a real-time run ends early on Ctrl-C.
SessionOptions session_options(const RunArguments& a, const std::filesystem::path& fmus) {
  SessionOptions options = a.options;
  options.output_dir = a.output_dir;
  options.fmu_dir = fmus;
  options.realtime_priority = !a.no_priority;
  if (!a.record_file.empty()) options.record = a.record_file;
  if (!options.offline) {
    options.stop = &g_stop_requested;
    struct sigaction action {};
    action.sa_handler = on_interrupt;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
  }
  if (a.view || a.mouse) {
    const SessionOptions::View v = view_options(a);
    options.view = v;
    options.browser_device = a.mouse;
    options.view_started = [address = v.address, token = v.token](std::uint16_t port) {
      std::cout << "live view: http://" << (address == "0.0.0.0" ? "127.0.0.1" : address) << ":" << port << "/"
                << (token.empty() ? "" : "?token=" + token) << std::endl;
    };
  }
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tissue-host: the real-time haptic host of the tissue FMUs"};
  app.require_subcommand(1);
  std::string fmu_dir;  // run, bench and compare
  bool quiet = false;   // run and compare

  RunArguments run_arguments;
  CLI::App* run = add_run_command(app, run_arguments, fmu_dir, quiet);
  std::string fmu_file;
  CLI::App* info = app.add_subcommand("info", "Describe an FMU (variables, capabilities)");
  info->add_option("fmu", fmu_file, "FMU file")->required()->check(CLI::ExistingFile);
  int bench_steps = 200;
  double bench_step_s = 0.01;
  CLI::App* bench = add_bench_command(app, bench_steps, bench_step_s, fmu_dir);
  CompareArguments compare_arguments;
  CLI::App* compare = add_compare_command(app, compare_arguments, fmu_dir, quiet);
  TimerArguments timer_arguments;
  CLI::App* timer = add_timer_command(app, timer_arguments);

  CLI11_PARSE(app, argc, argv);
  try {
    const std::filesystem::path fmus = fmu_dir.empty() ? default_fmu_dir() : std::filesystem::path(fmu_dir);
    if (run->parsed()) {
      return run_command(run_arguments.scenario_file, session_options(run_arguments, fmus), quiet,
                         run_arguments.duration_s);
    }
    if (info->parsed()) return info_command(fmu_file);
    if (bench->parsed()) return bench_command(fmus, bench_steps, bench_step_s);
    if (timer->parsed()) return timer_command(timer_arguments);
    if (compare->parsed()) {
      CompareOptions& options = compare_arguments.options;
      options.scenario_file = compare_arguments.scenario;
      if (!compare_arguments.settings_file.empty()) options.settings_file = compare_arguments.settings_file;
      options.output_dir = compare_arguments.output;
      options.fmu_dir = fmus;
      if (compare->count("--duration") > 0) options.duration_s = compare_arguments.duration_s;
      return compare_command(options, quiet, argc, argv);
    }
  } catch (const std::exception& error) {
    std::cerr << "tissue-host: " << error.what() << "\n";
    return 2;
  }
  return 0;
}
