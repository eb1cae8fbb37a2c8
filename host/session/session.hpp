// One haptic session (docs/DESIGN.md, "Host"; dissertation 5.1.3): the HapticLoop FMU ticked at 1 kHz
// on a haptic thread with absolute deadlines, the Tissue FMU stepped on a dynamics thread, the two
// exchanging snapshots (LatestValue) at the start and end of each tissue step; a device in, forces
// out; frames, a log and a summary written to one folder. `offline` runs the same schedule on one
// thread without sleeping: the result of tissue step k reaches the haptic loop at the start of slot
// k + 1 (the real-time worst case), so two offline runs are byte-identical.
#pragma once

#include "device/device.hpp"
#include "output/session_summary.hpp"
#include "importer/fmu3_instance.hpp"
#include "scenario/scenario.hpp"

#include <array>
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace tissue::host {

/// One Tissue doStep as an observer sees it (offline and real time, on the dynamics thread).
struct TissueStepInfo {
  std::uint64_t index = 0;                 ///< 0 for the first step
  double start_s = 0.0;                    ///< tissue time at the start of the step
  double reached_s = 0.0;                  ///< tissue time reached (the last good time after a discard)
  double cpu_s = 0.0;                      ///< CPU time of the doStep call (CLOCK_THREAD_CPUTIME_ID)
  DoStepResult result;                     ///< what doStep answered
  std::array<double, 3> contact_force_n{};  ///< the tissue's contact.force after the step
};

/// Watches the Tissue FMU of a session step by step (tissue-host compare records and measures
/// with it). Called on the thread that steps the tissue; the instance may be read, not stepped.
class TissueStepObserver {
 public:
  virtual ~TissueStepObserver() = default;
  /// After initialization, before the first step.
  virtual void started(Fmu3Instance& tissue) = 0;
  /// After each doStep and the session's read of the outputs.
  virtual void stepped(Fmu3Instance& tissue, const TissueStepInfo& step) = 0;
};

struct SessionOptions {
  std::filesystem::path output_dir = "session";
  bool offline = false;
  std::optional<std::filesystem::path> record;  ///< write the device poses as a replayable CSV
  std::filesystem::path fmu_dir;                ///< where Tissue.fmu and HapticLoop.fmu are by default
  std::ostream* progress = nullptr;             ///< a progress line while the run goes (nullptr: quiet)
  bool realtime_priority = true;                ///< try SCHED_FIFO for the two threads
  /// Called on the haptic thread right before its first tick (real time only); tests use it to
  /// watch that thread (e.g. count its allocations).
  std::function<void()> haptic_thread_started;
  /// Tissue parameters set over the scenario's (same name: replaced in place; else appended).
  std::vector<ParameterSetting> tissue_parameter_overrides;
  /// Sees every tissue step (nullptr: none; then doStep's CPU time is not measured).
  TissueStepObserver* tissue_observer = nullptr;
  /// false: no files at all (no folder, log, frames, PNG, summary), for runs measured in memory.
  bool write_outputs = true;
  /// The live view in the browser (real time only; VIEW_PROTOCOL.md).
  struct View {
    std::string address = "127.0.0.1";
    std::uint16_t port = 8080;  ///< 0: any free port
    std::string token;          ///< required when the address is not loopback
    std::filesystem::path static_dir;
  };
  std::optional<View> view;
  /// The mouse and keyboard of the view's pages drive the tool (replaces the scenario's device).
  bool browser_device = false;
  /// Called once the view listens, with its port (e.g. to print the address).
  std::function<void(std::uint16_t port)> view_started;
  /// Set (e.g. by Ctrl-C) to end a real-time run early; the outputs cover the time run.
  const std::atomic<bool>* stop = nullptr;
};

/// Runs the scenario; writes summary.json, log.csv, frames/*.vtu with surface.pvd and final.png into
/// options.output_dir. Throws ScenarioError / FmuError / std::runtime_error when it cannot start;
/// failures during the run are counted in the summary.
SessionSummary run_session(const Scenario& scenario, const SessionOptions& options);

/// The tissue parameters of a session: the scenario's with `overrides` set over them by name.
std::vector<ParameterSetting> with_overrides(std::vector<ParameterSetting> parameters,
                                             const std::vector<ParameterSetting>& overrides);

/// Limits the FMUs' solver libraries (OpenMP, OpenBLAS) to the calling thread, before the FMUs load;
/// once per process (setenv is not safe while other threads run: call it before starting any).
void keep_solver_libraries_on_the_calling_thread();

}  // namespace tissue::host
