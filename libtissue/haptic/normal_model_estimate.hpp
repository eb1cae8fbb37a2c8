// The contact model along the normal of a tissue that reports its force only (no K_c, no D_c), from
// its samples (issue 42, item 5). Such a tissue's normal force, one sample to the next, is taken to be
//   f_n = a + K p + c q,
// p the tool's depth along the contact normal and q its rate over the tissue's step (what the
// tissue's own viscosity answers). Two successive sample pairs give two equations in (K, c) once the
// constant a is differenced out:
//   df = K dp + c dq   for (pair before) and (this pair).
// Where the two pairs are independent enough (the motion changes speed), both are solved; otherwise
// c stays and K is the secant of the force left after c's part. A held force alone is a spring and a
// damper delayed by a sample period: at the 10-30 Hz a hand rings at, the damper's delay turns it
// into negative damping (a 2000 N/m, 20 N s/m wall at 100 Hz kept a 0.2 kg hand ringing at 18-36
// mm/s and gave a light one 28 mJ). With (K, c) known the renderer evaluates the local model at the
// hand's position and velocity now (f0 - K_c (x - x0) - D_c (v - v0)): no delay left.
#pragma once

#include <optional>

namespace tissue::haptic {

/// One pair of successive samples in contact, along the later one's normal.
struct NormalPair {
  double depth_change_m = 0.0;           ///< dp: how much deeper the tool went
  double rate_change_m_per_s = 0.0;      ///< dq: how much its depth rate changed
  double force_change_n = 0.0;           ///< df: how much the normal force on the tool grew
};

struct NormalModel {
  double stiffness_n_per_m = 0.0;   ///< K >= 0
  double damping_n_s_per_m = 0.0;   ///< c >= 0
};

struct NormalModelLimits {
  double max_stiffness_n_per_m = 5000.0;
  /// c is at most this times max_stiffness_n_per_m [s] (a relaxation time).
  double max_relaxation_s = 0.05;
  /// Below this depth change the secant is noise [m] (about a desktop device's resolution).
  double min_depth_change_m = 1e-6;
  /// A rate change times this [s] (a sample period) is compared with min_depth_change_m: a pair whose
  /// depth and rate both changed less says nothing (rounding; the joint solve would amplify it).
  double rate_time_scale_s = 0.01;
  /// The two pairs are solved together only when |det| is at least this fraction of the sum of
  /// the magnitudes of its two products (the motion changed speed between them).
  double min_independence = 0.2;
};

/// The model after `pair`: `last` updated from `pair` and `previous` (the pair before it, if both were
/// in contact). `damping_known`: c is the tissue's own (it reports D_c), only K is estimated.
NormalModel estimate_normal_model(const NormalModel& last, const NormalPair& pair,
                                  const std::optional<NormalPair>& previous, bool damping_known,
                                  const NormalModelLimits& limits);

}  // namespace tissue::haptic
