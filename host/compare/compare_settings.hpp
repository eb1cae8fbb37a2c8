// The integrator settings tissue-host compare runs: named sets of Tissue FMU parameter values
// (integrator.method, integrator.linearSolver, tolerances, caps, ...), each at a list of internal
// steps (stepSize) that divide the scenario's communication step, and the tight reference every
// run is measured against. A built-in default list, or a [compare] table in the scenario or in a
// --settings file:
//
//   [compare]
//   steps = [0.001, 0.01]                  # internal steps [s] of every setting (optional)
//   [compare.reference]                    # optional; default: IDA, rtol 1e-7, atol 1e-10, KLU
//   step = 0.001
//   parameters = { "integrator.method" = "ida", "integrator.idaRelativeTolerance" = 1e-7 }
//   [[compare.settings]]                   # optional; replaces the default list
//   name = "be-pcg-tol1e-3-cap10"
//   parameters = { "integrator.linearSolver" = "pcg", "integrator.pcgMaxIterations" = 10 }
//   steps = [0.01]                         # optional, this setting only
#pragma once

#include "compare/compare_table.hpp"
#include "importer/model_description.hpp"
#include "scenario/scenario.hpp"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace tissue::host {

/// One named setting: Tissue FMU parameter values by name (stepSize comes from the steps).
struct CompareSetting {
  std::string name;
  std::vector<ParameterSetting> parameters;
  std::vector<double> steps_s;  ///< internal steps of this setting; empty = the list's
};

/// What compare runs, before it is checked against the scenario and the FMU.
struct CompareSettingsList {
  std::vector<CompareSetting> settings;
  std::vector<double> steps_s;  ///< internal steps of every setting; empty = default_steps()
  std::string steps_key = "compare.steps";  ///< where steps_s came from, for messages
  CompareSetting reference;     ///< its steps_s: one step, or empty = the smallest of all runs
  bool built_in = true;         ///< the default list (settings the FMU lacks become skipped rows)
  bool built_in_reference = true;
  std::string origin = "built-in settings";  ///< where it came from, for messages
};

/// One run: a setting at one internal step, with every parameter it sets (stepSize included).
struct RunSpec {
  std::size_t index = 0;  ///< its row; the reference is row 0
  std::string setting;    ///< the setting's name
  bool is_reference = false;
  double step_s = 0.0;  ///< internal step (stepSize)
  std::vector<ParameterSetting> parameters;
  std::string skipped;  ///< why it is not run (the FMU lacks a parameter of a built-in setting)
};

/// How a row describes its setting (from its parameters, else the FMU's start values).
struct SettingDescription {
  std::string integrator;                     ///< item of integrator.method ("backwardEuler", "ida")
  std::string linear_solver;                  ///< item of integrator.linearSolver or integrator.idaLinearSolver
  std::optional<double> tolerance;            ///< PCG tolerance or IDA relative tolerance
  std::optional<std::int64_t> iteration_cap;  ///< PCG's iteration cap
  std::string material_model = DEFAULT_MATERIAL_MODEL;  ///< item of material.model
  [[nodiscard]] std::string family() const;   ///< "backwardEuler/pcg", for the plot's colours
};

/// The built-in list (docs/DESIGN.md, "tissue-host compare"): backward Euler with PCG at 1e-3 (caps 10,
/// 50) and 1e-6 (cap 1000), with CHOLMOD; IDA at rtol 1e-3 and 1e-5 with KLU, 1e-3 with Krylov;
/// reference IDA rtol 1e-7, atol 1e-10, max step 1 ms, KLU.
[[nodiscard]] CompareSettingsList default_settings();

/// Internal steps when none are given: 1 ms if it divides the communication step, and the
/// communication step itself.
[[nodiscard]] std::vector<double> default_steps(double communication_step_s);

/// The [compare] table of a TOML file, or nullopt if it has none. A table without `settings`
/// keeps the default list (and the default reference unless it gives one). Throws ScenarioError
/// naming the file and key for unknown keys, wrong types and non-positive steps.
[[nodiscard]] std::optional<CompareSettingsList> read_compare_table(const std::filesystem::path& file);

/// The runs in row order: the reference first, then each setting at each of its steps. Checks
/// against the scenario and the Tissue FMU's description; throws ScenarioError (naming the
/// origin, setting and key) for a step that does not divide the communication step, a duplicate
/// name, a parameter the FMU does not have (a built-in setting's run is marked skipped instead;
/// a built-in reference the FMU cannot run falls back to backward Euler with CHOLMOD at the
/// smallest step, said in `note`), or an enumeration item the FMU does not know.
[[nodiscard]] std::vector<RunSpec> plan_runs(const CompareSettingsList& list, const Scenario& scenario,
                                             const ModelDescription& tissue, std::string& note);

/// The descriptive columns of a run, from its parameters and the FMU's start values.
[[nodiscard]] SettingDescription describe_setting(const std::vector<ParameterSetting>& parameters,
                                                  const ModelDescription& tissue);

/// "1 ms", "0.5 ms", "10 ms" (for progress lines and labels).
[[nodiscard]] std::string step_label(double step_s);

}  // namespace tissue::host
