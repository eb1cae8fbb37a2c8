// The surface near a probe that does not touch it yet (issue 20): what a haptic loop needs to render
// the surface from the tick the tool crosses it, instead of a tissue step (and a sample period)
// later. The nearest point of the mesh's own surface within a margin of the probe's touching point,
// the outward normal of its triangle, and the elementLocal contact stiffness there
// (contact_stiffness.hpp: cheap, no factorization; the effective K_c follows once in contact).
#pragma once

#include "core/tissue.hpp"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace tissue {

struct NearSurface {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  ///< unit, outward
  Eigen::Matrix3d stiffness_n_per_m = Eigen::Matrix3d::Zero();
  double distance_m = 0.0;  ///< from the touching point to `point_m`
};

/// Nothing unless the tool is a probe with contact on, not in contact, and a triangle of the mesh's
/// surface (not a cut face) lies within `margin_m` (> 0) of its touching point; `hits` is scratch.
std::optional<NearSurface> near_surface(const Tissue& tissue, double margin_m,
                                        std::vector<SurfaceBvh::SphereHit>& hits);

}  // namespace tissue
