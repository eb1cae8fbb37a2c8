// What the haptic loop receives from the tissue now and then (30-1000 Hz): the tissue's latest
// contact outputs and the tool position they were computed for; and the tool modes.
//
// Sign convention (used throughout tissue::haptic): every force is the force ON THE TOOL (the
// hand), in N. K_c is the stiffness of the tissue at the contact point as the tool sees it:
// moving the tool by dx changes the force on it by -K_c dx. K_c is symmetric positive
// semi-definite, so pushing deeper (dx = -d n, d > 0, n the outward normal) adds d K_c n, whose
// normal part d n^T K_c n >= 0 pushes the tool out harder. (docs/DESIGN.md, "Haptic loop": the
// architecture writes f = f0 + K_c (x - x0), the same model with K_c seen from the tissue's side,
// i.e. as the stiffness of the force the tool exerts on the tissue.)
#pragma once

#include "ports/tool.hpp"

#include <Eigen/Core>

namespace tissue::haptic {

/// One tissue update. A sample with contact_active == false renders no contact force (its contact
/// fields may then be zero), unless surface_near: then the contact point, normal and K_c describe the
/// surface next to the tool, rendered as a plane from the tick the tool crosses it (issue 20);
/// blade_depth_m is used in scalpel mode whether in contact or not.
struct TissueSample {
  double time_s = 0.0;  ///< tissue time at which it was computed (kept for logging only)
  bool contact_active = false;
  bool surface_near = false;  ///< not in contact, the surface within the tissue's margin of the tool
  Eigen::Vector3d contact_point_m = Eigen::Vector3d::Zero();  ///< god-object on the deformed surface
  Eigen::Vector3d contact_normal = Eigen::Vector3d::Zero();   ///< unit outward surface normal there
  Eigen::Vector3d force_on_tool_n = Eigen::Vector3d::Zero();  ///< f0: the tissue's force on the tool at x0
  /// K_c [N/m], 3x3, symmetric positive semi-definite: d(force on tool) = -K_c d(tool position).
  Eigen::Matrix3d contact_stiffness_n_per_m = Eigen::Matrix3d::Zero();
  /// D_c [N s/m], 3x3, symmetric positive semi-definite: d(force on tool) = -D_c d(tool velocity); the
  /// viscous part of f0 is D_c times the tool's velocity over the tissue's step.
  Eigen::Matrix3d contact_damping_n_s_per_m = Eigen::Matrix3d::Zero();
  Eigen::Vector3d tool_position_m = Eigen::Vector3d::Zero();  ///< x0: the tool position f0 is for
  double blade_depth_m = 0.0;  ///< length of the scalpel's edge inside the tissue (0: not cutting)
};

/// What prepare_sample() had to repair.
struct SampleRepair {
  bool stiffness_repaired = false;  ///< K_c was not symmetric PSD beyond rounding and was projected
  bool damping_repaired = false;    ///< D_c, the same
};

/// Checks a sample and brings it to the form the renderer relies on, in place:
/// * refuses (std::invalid_argument naming the field, sample unchanged) any non-finite number, a
///   negative blade depth, and, when contact is active or the surface near, a normal whose length differs from 1 by
///   more than 1e-6;
/// * renormalizes the normal to unit length;
/// * replaces K_c and D_c each by the nearest (Frobenius) symmetric PSD matrix: the symmetric part with its
///   negative eigenvalues set to 0. An antisymmetric part (a curl force field) or a negative
///   eigenvalue would make the rendered contact an energy source on a closed path; removing them
///   only removes that. No allocation (fixed-size 3x3 eigen-solver).
SampleRepair prepare_sample(TissueSample& sample);

}  // namespace tissue::haptic
