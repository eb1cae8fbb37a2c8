// The contact force between two tissue samples: the intermediate representation (a local
// first-order model of the tissue at the contact, evaluated at 1 kHz; Cavusoglu and Tendick 2000,
// "Multirate simulation for high fidelity haptic interaction with deformable objects in virtual
// environments", ICRA) and the unilateral constraint against the contact plane. Two functions,
// one job each; the sign convention is the one in tissue_sample.hpp (force on the tool).
#pragma once

#include "haptic/tissue_sample.hpp"

#include <Eigen/Core>

namespace tissue::haptic {

/// Intermediate representation: f = f0 - K_c (x - x0), the tissue's force on the tool at the tool
/// position x, linearized about the sample's tool position x0. Ignores contact_active and the
/// contact plane (unilateral_force() applies them).
Eigen::Vector3d intermediate_force(const TissueSample& sample, const Eigen::Vector3d& tool_position_m);

/// The contact can push the tool out but never pull it in:
/// * the tool on the outer side of the contact plane (through contact_point_m, normal
///   contact_normal) by more than the pressed surface's rebound feels nothing: (x - p) . n > f_n / k_n
///   (f_n = f0 . n, k_n = n^T K_c n; 0 when either is not positive). The contact point is the
///   surface as the sample left it, pressed down to within |f| / k_spring (microns) of the tool; a
///   tool drawn back is followed by the surface until the tissue's force has relaxed, as the linear
///   model says (issue 20: with the plane alone, a hand easing off a 1 N press by 10 um lost the whole
///   force and chattered at 23 Hz). The same rule holds the Tissue's contact (PointContact::update);
/// * a force whose normal component is negative (it would pull the tool into the surface) is
///   dropped altogether, tangential part included: a frictionless contact (the tissue's contact is,
///   docs/DESIGN.md, "Haptic loop") that carries no normal load carries no tangential load either. The step this
///   makes where f . n crosses 0 is at most the tangential part, and the rate limiter smooths it.
/// Otherwise `force_n` is returned unchanged. The result r satisfies r . n >= 0.
Eigen::Vector3d unilateral_force(const Eigen::Vector3d& force_n, const TissueSample& sample,
                                 const Eigen::Vector3d& tool_position_m);

/// The surface next to a tool that was not in contact at the sample (TissueSample::surface_near):
/// the plane through contact_point_m with normal n pushes a tool that crossed it out along n with
/// (n^T K_c n) times the depth. So a contact starts at the tick the tool crosses the surface, not a
/// tissue step and a sample period later (issue 20), and the tissue's own contact
/// (intermediate_force) takes over with the next sample. Ignores the plane's side (unilateral_force()
/// applies it).
Eigen::Vector3d near_surface_force(const TissueSample& sample, const Eigen::Vector3d& tool_position_m);

/// The contact's viscous force, -D_c (v - v0) - (B n n^T + T K_c) v, v the hand's velocity now:
/// * -D_c (v - v0): the tissue's own viscosity (TissueSample::contact_damping_n_s_per_m) at the
///   hand's velocity now instead of held in f0 at the tool's velocity over the tissue's step, v0. Held,
///   it acts a sample period or two late, which at the 10-30 Hz a hand rings at on a stiff contact is
///   a negative damping (issue 20: the frog at 1 MPa with damping.beta 0.01 chattered at 20 Hz).
/// * -T K_c v: a spring K held over each tick T acts like the spring with a negative damping K T / 2
///   (Colgate and Schenkel 1997); a virtual damper B' fed the backward-difference velocity keeps a
///   hand of damping b stable while K T / 2 < b + B' (Gil, Avello, Rubio and Florez 2004, "Stability
///   analysis of a 1 DOF haptic interface using the Routh-Hurwitz criterion", IEEE Trans. Control
///   Systems Technology 12(4)). T K_c gives back twice the hold's loss along every direction the
///   contact is stiff in, so that any hand (b >= 0) is stable on any contact.
/// * -B n n^T v: a damping of the user's choice along the normal (contact.damping).
/// `hold_s` is T (0: no hold damping).
/// The last two are dissipative (K_c PSD, prepare_sample); the first is the tissue's. Ignores the
/// plane's side (unilateral_force() applies it).
Eigen::Vector3d contact_damping_force(const TissueSample& sample, const Eigen::Vector3d& velocity_m_per_s,
                                      const Eigen::Vector3d& sample_tool_velocity_m_per_s,
                                      double damping_n_s_per_m, double hold_s);

}  // namespace tissue::haptic
