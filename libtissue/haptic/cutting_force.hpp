// The force the hand feels while the scalpel cuts (beyond the source dissertation, which left the
// cutting force as future work). Fracture mechanics (Mahvash and Hayward, "Haptic rendering of
// cutting: a fracture mechanics approach", Haptics-e 2(3), 2001): the work to extend a crack is
// the fracture toughness J_c times the new crack area, so a blade whose edge is d deep in the
// tissue and advances by ds creates d ds of crack and meets a force J_c d along its motion.
// Blade friction adds mu_b d (force per metre of edge in the tissue). Near zero speed the force is
// smoothed with tanh(|v| / v_ref), so it fades continuously instead of flipping sign with the
// velocity noise (no chatter):
//   f_cut = -(J_c + mu_b) d tanh(|v| / v_ref) v / |v|,
// v the filtered hand velocity (velocity_filter.hpp). The filter lags, so when the hand reverses,
// -v can point along the hand's actual motion; the component of f_cut along the last measured
// motion (backward difference), if it pushes that way, is removed: the cutting force only ever
// resists the hand.
//
// Default J_c = 164 J/m^2: bovine liver, needle-insertion experiments (Gokgol, Basdogan and
// Canadinc 2012, "Estimation of fracture toughness of liver tissue: experiments and validation",
// Med. Eng. Phys. 34(7):882-891, J = 164 +- 6 J/m^2). Other tissues are far tougher (a review table:
// porcine skin 1.1-30 kJ/m^2, porcine liver 76-225 J/m^2; Chinese J. Mech. Eng. 2022,
// doi:10.1186/s10033-022-00767-4, table 2): a 5 mm deep cut in liver meets 0.82 N, one in skin would
// exceed any desktop device and is clamped.
#pragma once

#include <Eigen/Core>

namespace tissue::haptic {

struct CuttingSettings {
  /// J_c [J/m^2], finite and >= 0 (0: the blade cuts without resistance). See the file comment.
  double fracture_toughness_j_per_m2 = 164.0;
  /// Friction of the blade's sides per metre of edge in the tissue [N/m], finite and >= 0.
  /// 0 by default: no published figure for scalpel friction in soft tissue was found.
  double blade_friction_n_per_m = 0.0;
  /// v_ref of the tanh smoothing [m/s], finite and > 0. 0.01 m/s: the force reaches 76% of its
  /// value at 1 cm/s and 99.5% at 3 cm/s (a slow, deliberate incision), while the filtered
  /// quantization noise of a desktop device (one 0.055 mm count per 1 ms tick, low-passed at 30 Hz)
  /// stays around 0.01-0.02 m/s; an assumption to tune on the device.
  double smoothing_speed_m_per_s = 0.01;
};

/// Throws ParameterError naming the setting unless all are in range.
void validate(const CuttingSettings& settings);

/// The cutting force on the tool (see the file comment); zero for blade_depth_m <= 0 or a hand at
/// rest. `velocity_m_per_s`: filtered hand velocity; `motion_m_per_s`: the last backward difference.
/// The result f satisfies f . motion <= 0 and |f| <= (J_c + mu_b) d.
Eigen::Vector3d cutting_force(const CuttingSettings& settings, double blade_depth_m,
                              const Eigen::Vector3d& velocity_m_per_s, const Eigen::Vector3d& motion_m_per_s);

}  // namespace tissue::haptic
