// recommend (see recommendation.hpp).
#include "compare/recommendation.hpp"

#include "compare/compare_settings.hpp"

#include <cstdio>

namespace tissue::host {
namespace {

std::string number_text(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

std::string bounds(const UseCase& use) {
  std::string text;
  if (use.max_step_s) text += "internal step <= " + step_label(*use.max_step_s);
  if (use.max_cpu_s_per_sim_s) {
    text += (text.empty() ? "" : ", ") + std::string("cost <= ") + number_text(*use.max_cpu_s_per_sim_s) +
            " CPU s per simulated s";
  }
  return text.empty() ? "any step and cost" : text;
}

}  // namespace

std::vector<UseCase> default_use_cases() {
  return {{"1 kHz haptic", 1e-3, 0.5}, {"100 Hz visual", 1e-2, 0.5}, {"offline accuracy", std::nullopt, std::nullopt}};
}

std::vector<Recommendation> recommend(const std::vector<CompareRow>& rows, const std::vector<UseCase>& uses) {
  std::vector<Recommendation> recommendations;
  for (const UseCase& use : uses) {
    Recommendation r{use, std::nullopt, {}};
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const CompareRow& row = rows[i];
      if (row.is_reference() || !row.comparable()) continue;
      if (use.max_step_s && row.internal_step_s > *use.max_step_s * (1.0 + 1e-9)) continue;
      if (use.max_cpu_s_per_sim_s && *row.cpu_s_per_sim_s > *use.max_cpu_s_per_sim_s) continue;
      if (r.row) {
        const CompareRow& best = rows[*r.row];
        const bool better = *row.rms_error_m < *best.rms_error_m ||
                            (*row.rms_error_m == *best.rms_error_m && *row.cpu_s_per_sim_s < *best.cpu_s_per_sim_s);
        if (!better) continue;
      }
      r.row = i;
    }
    if (r.row) {
      const CompareRow& best = rows[*r.row];
      r.text = use.name + ": " + best.setting + " @ " + step_label(best.internal_step_s) + " (" + best.family() +
               ", RMS error " + number_text(*best.rms_error_m) + " m, " + number_text(*best.cpu_s_per_sim_s) +
               " CPU s per simulated s)";
    } else {
      r.text = use.name + ": no setting qualifies (" + bounds(use) + ", no failed step)";
      // Say how far off the cheapest one at the use's step is, so that the gap is a number.
      std::optional<std::size_t> cheapest;
      for (std::size_t i = 0; i < rows.size(); ++i) {
        const CompareRow& row = rows[i];
        if (row.is_reference() || !row.comparable()) continue;
        if (use.max_step_s && row.internal_step_s > *use.max_step_s * (1.0 + 1e-9)) continue;
        if (!cheapest || *row.cpu_s_per_sim_s < *rows[*cheapest].cpu_s_per_sim_s) cheapest = i;
      }
      if (cheapest) {
        const CompareRow& row = rows[*cheapest];
        r.text += "; the cheapest at that step: " + row.setting + " @ " + step_label(row.internal_step_s) + ", " +
                  number_text(*row.cpu_s_per_sim_s) + " CPU s per simulated s, RMS error " +
                  number_text(*row.rms_error_m) + " m";
      }
    }
    recommendations.push_back(std::move(r));
  }
  return recommendations;
}

}  // namespace tissue::host
