// tissue-host compare: one scenario run offline under a list of integrator settings, each against
// a tight reference, for speed against accuracy (docs/DESIGN.md, "tissue-host compare"). The reference
// runs first (rank 0); the other runs are dealt over the processes (RunDistribution: one, or the
// ranks of an MPI job) and, inside each, over `jobs` threads; rank 0 gathers the rows and writes
// compare.csv, compare.png, recommendation.txt and compare.json.
#pragma once

#include "compare/compare_report.hpp"
#include "compare/run_distribution.hpp"

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <vector>

namespace tissue::host {

struct CompareOptions {
  std::filesystem::path scenario_file;
  /// A TOML file with a [compare] table; else the scenario's [compare]; else the built-in list.
  std::optional<std::filesystem::path> settings_file;
  std::filesystem::path output_dir = "compare";
  std::filesystem::path fmu_dir;     ///< where Tissue.fmu and HapticLoop.fmu are
  int jobs = 1;                      ///< threads per process, >= 1
  std::vector<double> steps_s;       ///< replaces every setting's internal steps (--steps)
  std::optional<double> duration_s;  ///< the scenario's duration instead (--duration)
  std::ostream* progress = nullptr;  ///< the progress line (rank 0; nullptr: quiet)
  bool progress_in_place = true;     ///< one line rewritten with '\r' (else one line per run)
};

/// Runs the comparison; on rank 0 writes the outputs into options.output_dir and returns the
/// report (other ranks: an empty report). Throws ScenarioError / FmuError / std::runtime_error for
/// what stops it before the runs (bad scenario or settings, jobs < 1, a failed reference); a run
/// that fails is a row saying why.
CompareReport run_compare(const CompareOptions& options, RunDistribution& distribution);

}  // namespace tissue::host
