// Which setting to use for what, from the rows of tissue-host compare. A use is an upper bound on
// the internal step and on the cost (CPU s per simulated s; 0.5 leaves half of a core to the
// haptic loop and the rest); among the comparable rows (an error, a cost, no failed step, not the
// reference) that fit, the lowest error wins, ties going to the cheaper.
#pragma once

#include "compare/compare_table.hpp"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace tissue::host {

struct UseCase {
  std::string name;                           ///< "1 kHz haptic"
  std::optional<double> max_step_s;           ///< internal step at most this
  std::optional<double> max_cpu_s_per_sim_s;  ///< cost at most this
};

/// "1 kHz haptic" (step <= 1 ms, cost <= 0.5), "100 Hz visual" (step <= 10 ms, cost <= 0.5),
/// "offline accuracy" (no bound).
[[nodiscard]] std::vector<UseCase> default_use_cases();

struct Recommendation {
  UseCase use;
  std::optional<std::size_t> row;  ///< index into the rows; nullopt: no setting qualifies
  std::string text;                ///< one line, e.g. "1 kHz haptic: be-cholmod @ 1 ms (...)"
};

[[nodiscard]] std::vector<Recommendation> recommend(const std::vector<CompareRow>& rows,
                                                    const std::vector<UseCase>& uses = default_use_cases());

}  // namespace tissue::host
