// The hand velocity the cutting force needs: the backward difference of the device positions,
// smoothed by a first-order low-pass (exponential smoothing, the discretization of
// tau dv/dt = v_raw - v with tau = 1 / (2 pi f_c)):
//   v_k = v_{k-1} + a (v_raw_k - v_{k-1}),  a = dt / (dt + tau).
// Backward difference cascaded with a low-pass is the usual velocity estimate of haptic
// interfaces (Chawda, Celik and O'Malley 2014, J. Dyn. Sys., Meas., Control, doi:10.1115/1.4028526).
// Its lag is tau (5.3 ms at 30 Hz); the passivity controller uses the raw backward difference.
#pragma once

#include <numbers>

namespace tissue::haptic {

/// The gain a of the first-order low-pass for a tick of dt_s and a cut-off of cutoff_hz (both > 0).
inline double low_pass_gain(double dt_s, double cutoff_hz) {
  const double tau_s = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
  return dt_s / (dt_s + tau_s);
}

}  // namespace tissue::haptic
