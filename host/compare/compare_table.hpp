// The rows of tissue-host compare and compare.csv. One row per (setting, internal step); a value
// that does not exist (no error for a run that failed, no iteration cap for CHOLMOD) is an empty
// field. Numbers are written in shortest round-trip form (std::to_chars), so a row read back
// (parse_csv_row) is bit for bit the row written: the MPI gather sends rows as these lines.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tissue::host {

/// material.model's item when a setting does not set it (the Tissue FMU's start).
inline constexpr const char* DEFAULT_MATERIAL_MODEL = "corotationalLinear";

/// The plot's series of a setting: "integrator/linear solver", and "/stableNeoHookean" when the
/// material model is not DEFAULT_MATERIAL_MODEL.
[[nodiscard]] std::string setting_family(const std::string& integrator, const std::string& linear_solver,
                                         const std::string& material_model);

struct CompareRow {
  std::string setting;  ///< "reference" for the reference run
  std::string integrator, linear_solver;
  std::string material_model = DEFAULT_MATERIAL_MODEL;  ///< item of material.model
  std::optional<double> tolerance;
  std::optional<std::int64_t> iteration_cap;
  double internal_step_s = 0.0;
  std::optional<double> cpu_s_per_sim_s;
  std::optional<double> rms_error_m, max_error_m, force_error_n, energy_drift_j;
  std::optional<std::uint64_t> iterations;
  std::uint64_t failures = 0;
  bool pareto = false;
  std::string note;  ///< why a value is missing (not run, not compared, first error)

  [[nodiscard]] bool is_reference() const { return setting == "reference"; }
  /// Has an error and a cost, and no failed step: a candidate for the front and the recommendations.
  [[nodiscard]] bool comparable() const;
  [[nodiscard]] std::string family() const { return setting_family(integrator, linear_solver, material_model); }
};

/// The header line of compare.csv (no newline).
[[nodiscard]] std::string csv_header();
/// One row as a CSV line (no newline); the note is quoted when it holds a comma or a quote.
[[nodiscard]] std::string csv_row(const CompareRow& row);
/// The row of a line csv_row wrote; throws std::runtime_error for anything else.
[[nodiscard]] CompareRow parse_csv_row(std::string_view line);
/// Writes the header and the rows (replacing the file); throws std::runtime_error.
void write_csv(const std::filesystem::path& file, const std::vector<CompareRow>& rows);

}  // namespace tissue::host
