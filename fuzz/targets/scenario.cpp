// Door: a scenario file (host/scenario: load_scenario -> parse_scenario, what `tissue-host run`
// reads), with relative paths anchored in host/scenarios/. Structure-aware (support/toml_mutator).
// Promise: refused with a ScenarioError naming the key and the reason, or accepted with a positive,
// finite duration and steps, and a haptic period no longer than the tissue's step.
#include "scenario/scenario.hpp"
#include "support/promise.hpp"
#include "support/toml_mutator.hpp"

#include <cmath>
#include <string>

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  return tissue::fuzz::mutate_toml(data, size, max_size, seed);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue::host;
  Scenario scenario;
  try {
    scenario = parse_scenario(std::string(tissue::fuzz::as_text(data, size)),
                              std::filesystem::path(TISSUE_SCENARIO_DIR) / "fuzz.toml");
  } catch (const ScenarioError& error) {
    tissue::fuzz::require_message(error.what(), "scenario");
    return 0;
  }
  const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
  if (!positive(scenario.duration_s) || !positive(scenario.tissue_step_s) || !positive(scenario.haptic_period_s))
    tissue::fuzz::broken("a scenario accepted with a duration or step that is not positive and finite");
  if (scenario.haptic_period_s > scenario.tissue_step_s)
    tissue::fuzz::broken("a scenario accepted with a haptic period longer than the tissue step");
  return 0;
}
