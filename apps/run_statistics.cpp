// Order statistics for the apps' reports.
#include "run_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace tissue::apps {

Summary summarize(std::vector<double> samples) {
  Summary summary;
  if (samples.empty()) return summary;
  std::sort(samples.begin(), samples.end());
  const auto rank = [&](double fraction) {
    const auto index = static_cast<size_t>(std::ceil(fraction * static_cast<double>(samples.size()))) - 1;
    return samples[std::min(index, samples.size() - 1)];
  };
  const size_t n = samples.size();
  summary.median = n % 2 == 1 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
  summary.p90 = rank(0.9);
  summary.max = samples.back();
  summary.mean = std::accumulate(samples.begin(), samples.end(), 0.0) / static_cast<double>(n);
  return summary;
}

}  // namespace tissue::apps
