// estimate_normal_model (see normal_model_estimate.hpp).
#include "haptic/normal_model_estimate.hpp"

#include <algorithm>
#include <cmath>

namespace tissue::haptic {

NormalModel estimate_normal_model(const NormalModel& last, const NormalPair& pair,
                                  const std::optional<NormalPair>& previous, bool damping_known,
                                  const NormalModelLimits& limits) {
  const double max_damping = limits.max_relaxation_s * limits.max_stiffness_n_per_m;
  const auto informative = [&](const NormalPair& p) {
    return std::max(std::abs(p.depth_change_m), limits.rate_time_scale_s * std::abs(p.rate_change_m_per_s)) >
           limits.min_depth_change_m;
  };
  if (!damping_known && previous && informative(pair) && informative(*previous)) {
    // [dp dq; dp' dq'] (K, c) = (df, df')
    const double det = pair.depth_change_m * previous->rate_change_m_per_s -
                       pair.rate_change_m_per_s * previous->depth_change_m;
    const double scale = std::abs(pair.depth_change_m * previous->rate_change_m_per_s) +
                         std::abs(pair.rate_change_m_per_s * previous->depth_change_m);
    if (scale > 0.0 && std::abs(det) >= limits.min_independence * scale) {
      const double stiffness = (pair.force_change_n * previous->rate_change_m_per_s -
                                pair.rate_change_m_per_s * previous->force_change_n) / det;
      const double damping = (pair.depth_change_m * previous->force_change_n -
                              pair.force_change_n * previous->depth_change_m) / det;
      if (std::isfinite(stiffness) && std::isfinite(damping) && stiffness >= 0.0 &&
          stiffness <= limits.max_stiffness_n_per_m && damping >= 0.0 && damping <= max_damping) {
        return {stiffness, damping};
      }
    }
  }
  NormalModel model = last;
  if (std::abs(pair.depth_change_m) > limits.min_depth_change_m) {
    const double secant =
        (pair.force_change_n - last.damping_n_s_per_m * pair.rate_change_m_per_s) / pair.depth_change_m;
    if (std::isfinite(secant)) model.stiffness_n_per_m = std::clamp(secant, 0.0, limits.max_stiffness_n_per_m);
  }
  return model;
}

}  // namespace tissue::haptic
