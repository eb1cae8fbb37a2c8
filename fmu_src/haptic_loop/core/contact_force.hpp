// The contact force between two tissue samples: the intermediate representation (a local
// first-order model of the tissue at the contact, evaluated at 1 kHz; Cavusoglu and Tendick 2000,
// "Multirate simulation for high fidelity haptic interaction with deformable objects in virtual
// environments", ICRA) and the unilateral constraint against the contact plane. Two functions,
// one job each; the sign convention is the one in tissue_sample.hpp (force on the tool).
#pragma once

#include "haptic_loop/core/tissue_sample.hpp"

#include <Eigen/Core>

namespace tissue::haptic {

/// Intermediate representation: f = f0 - K_c (x - x0), the tissue's force on the tool at the tool
/// position x, linearized about the sample's tool position x0. Ignores contact_active and the
/// contact plane (unilateral_force() applies them).
Eigen::Vector3d intermediate_force(const TissueSample& sample, const Eigen::Vector3d& tool_position_m);

/// The contact can push the tool out but never pull it in:
/// * the tool on the outer side of the contact plane (through contact_point_m, normal
///   contact_normal; (x - p) . n > 0) feels nothing;
/// * a force whose normal component is negative (it would pull the tool into the surface) is
///   dropped altogether, tangential part included: a frictionless contact (the tissue's contact is,
///   docs/DESIGN.md) that carries no normal load carries no tangential load either. The step this
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

/// Viscous damping of the contact along its normal, -B (v . n) n: what keeps a light, lightly damped
/// hand from ringing on a stiff contact rendered at a finite rate. A zero-order-hold spring K at tick T
/// loses damping K T / 2 (Colgate and Schenkel 1997); with a virtual damper B the rendered wall is
/// stable for a hand of damping b while K T / 2 < b + B (Gil, Avello, Rubio and Florez 2004, "Stability
/// analysis of a 1 DOF haptic interface using the Routh-Hurwitz criterion", IEEE Trans. Control
/// Systems Technology 12(4)). Ignores the plane's side (unilateral_force() applies it).
Eigen::Vector3d contact_damping_force(const TissueSample& sample, const Eigen::Vector3d& velocity_m_per_s,
                                      double damping_n_s_per_m);

}  // namespace tissue::haptic
