// Time-domain passivity observer (PO) and controller (PC) of Hannaford and Ryu 2002 ("Time-domain
// passivity control of haptic interfaces", IEEE Trans. Robotics and Automation 18(1):1-10), for
// the one-port behind the device in impedance causality: device position (velocity) in, force
// out. Everything behind the device, the renderer with its stale tissue samples included, is the
// one-port; it is passive while the energy it has absorbed, E = -sum f . dx, stays >= 0.
//
// Observer: books each completed tick with the force that was actually held on the device over it
// (after clamp, rate limit and the controller) and the displacement the device measured across it,
// E_k = E_{k-1} - f_{k-1} . (x_k - x_{k-1}). This is the paper's E_k = E_{k-1} - f v dt with each
// force paired with the motion it acted over: with a zero-order-hold device and exact positions the
// sum is the exact work, and the device-rate hold leak of a sampled spring K (K |dx|^2 / 2 per tick;
// Colgate and Schenkel 1997, J. Robotic Systems 14(1)) is observed too. Pairing f_k with the
// backward difference v_k = (x_k - x_{k-1}) / dt instead books each tick short by K |dx|^2: in the
// 10 s wall test (test_passivity.cpp) the hand then gains 4.4e-4 J with the controller on.
//
// Controller: before commanding f_k it predicts the tick ahead with the paper's step,
// E_pred = E_k - f_k . v_k dt (v_k the backward difference), and if E_pred < 0 adds the variable
// damping alpha = -E_pred / (dt |v_k|^2), force -alpha v_k, which dissipates exactly the predicted
// excess. Whatever the prediction misses (a change of velocity within the tick) or the force limits
// keep the controller from commanding is booked exactly at the next tick and dissipated then. So
// while the limits let the controller act, the one-port's energy never falls below minus one tick's
// prediction error, |f| |a| dt^2 (a the hand's acceleration); where they hold it back (a deficit
// larger than max_force_n or the rate limit can dissipate in one tick), the deficit stays booked
// and is dissipated over the next ticks.
//
// The damping is bounded (issue 20): -alpha v held over a tick slows a hand of mass m by about
// alpha dt / m of its speed, and past 1 it reverses the hand within the tick, so that the "damping"
// pushes it back the way it came: the controller then gives energy, the observer books a larger
// deficit and the next alpha is larger still (a 0.2 kg hand on a 2000 N/m wall with maxForce
// 100 N gained 2 J). alpha <= m_min / (2 dt) slows the lightest hand allowed by at most half per
// tick, so the damping force opposes the motion over the whole tick and only dissipates; a deficit
// it cannot take in one tick stays booked and is taken over the next ones. Bounding the
// controller's dissipation per tick is the idea of Ryu, Kim and Hannaford 2004 ("Sampled- and
// continuous-time passivity and stability of virtual environments", IEEE Trans. Robotics 20(4)) and
// of energy-bounding schemes (Kim and Ryu 2004).
#pragma once

#include <Eigen/Core>

namespace tissue::haptic {

class PassivityObserver {
 public:
  /// Books one completed tick: `held_force_n`, the force commanded on the device during it,
  /// `held_damping_n` its part added by the controller, `displacement_m` the device's motion
  /// across it (x_k - x_{k-1}).
  void book(const Eigen::Vector3d& held_force_n, const Eigen::Vector3d& held_damping_n,
            const Eigen::Vector3d& displacement_m);
  /// A positive balance is energy the one-port absorbed (the contact's stored spring energy, the
  /// cutting work). While the loop is idle (no force rendered, none commanded) nothing can be
  /// stored any more, so the credit is dropped: it could otherwise pay for an active contact later.
  /// A deficit (< 0) is kept until the controller has dissipated it.
  void drop_credit();

  /// E [J]: energy the one-port absorbed through the last completed tick; < 0: it gave energy.
  double energy_j() const { return m_energy_j; }
  /// Energy the controller's damping took from the hand over the completed ticks [J].
  double dissipated_j() const { return m_dissipated_j; }
  /// For a state restore (the renderer checks the values).
  void set(double energy_j, double dissipated_j) {
    m_energy_j = energy_j;
    m_dissipated_j = dissipated_j;
  }

 private:
  double m_energy_j = 0.0;
  double m_dissipated_j = 0.0;
};

struct PassivityAction {
  Eigen::Vector3d damping_force_n = Eigen::Vector3d::Zero();  ///< -alpha v, to add to the command
  double damping_n_s_per_m = 0.0;                             ///< alpha >= 0
  double predicted_energy_j = 0.0;                            ///< E_pred = E - f . v dt, before the damping
};

/// The controller's step (see the file comment) for the observed energy `energy_j`, the force about
/// to be commanded and the backward-difference velocity, alpha at most `max_damping_n_s_per_m`. No
/// action (alpha = 0) when E_pred >= 0 or the device is at rest (|v| < 1e-9 m/s: no energy can flow,
/// and alpha would overflow).
PassivityAction passivity_damping(double energy_j, const Eigen::Vector3d& force_n,
                                  const Eigen::Vector3d& velocity_m_per_s, double dt_s,
                                  double max_damping_n_s_per_m);

}  // namespace tissue::haptic
