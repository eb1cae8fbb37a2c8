// Order statistics of per-step timings for the apps' reports (median, p90, max, mean).
#pragma once

#include <vector>

namespace tissue::apps {

struct Summary {
  double median = 0.0;
  double p90 = 0.0;
  double max = 0.0;
  double mean = 0.0;
};

/// Nearest-rank percentiles of `samples` (empty -> all zero).
Summary summarize(std::vector<double> samples);

}  // namespace tissue::apps
