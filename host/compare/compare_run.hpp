// One run of tissue-host compare: the scenario offline through the session (its schedule, the
// HapticLoop in the loop), with one setting's Tissue parameters set over the scenario's, the CPU
// time of every Tissue doStep measured (CLOCK_THREAD_CPUTIME_ID), the surface, contact force and
// energy compared with the reference at each communication point, or recorded as the reference.
// Each run loads its own FMUs (host/importer), so runs may go on several threads at once.
#pragma once

#include "compare/compare_metrics.hpp"
#include "compare/compare_settings.hpp"
#include "scenario/scenario.hpp"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace tissue::host {

/// What one run measured.
struct RunOutcome {
  bool ran = false;                         ///< the session ran (parameters accepted, FMUs loaded)
  double cpu_s = 0.0;                       ///< CPU time of the Tissue doStep calls
  double simulated_s = 0.0;                 ///< tissue time the steps covered
  std::uint64_t failures = 0;               ///< doSteps that answered fmi3Discard, fmi3Error or fmi3Fatal
  std::optional<std::uint64_t> iterations;  ///< integrator.iterations at the end, if the FMU has it
  ErrorMetrics errors;                      ///< against the reference (invalid without one)
  std::string note;                         ///< why it did not run or cannot be compared; the first error

  /// CPU seconds per simulated second, if anything was simulated.
  [[nodiscard]] std::optional<double> cpu_s_per_sim_s() const;
};

/// Runs `run` offline. With `reference`, compares each communication point with it; with
/// `record`, records every point into it (the reference run). Never throws for a setting the FMU
/// refuses or a failing step: that is in the outcome's note.
[[nodiscard]] RunOutcome run_measured(const Scenario& scenario, const RunSpec& run,
                                      const std::filesystem::path& fmu_dir, const ReferenceTrace* reference,
                                      ReferenceTrace* record);

}  // namespace tissue::host
