// The surface near a probe that does not touch it yet (issue 20): what a haptic loop needs to render
// the surface from the tick the tool crosses it, instead of a tissue step (and a sample period)
// later. The nearest point of the mesh's own surface within a margin of the probe's touching point,
// the outward normal of its triangle, and the elementLocal contact stiffness there
// (contact_stiffness.hpp: cheap, no factorization; the effective K_c follows once in contact).
#pragma once

#include "core/collide/surface_bvh.hpp"
#include "core/fem/corotational.hpp"
#include "core/mesh/topology.hpp"

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

/// The nearest triangle of the mesh's surface `surface` (not a cut face: the BVH's ids from
/// surface.triangles.size() on) within `margin_m` (> 0) of `touching_point_m`, in `bvh` fitted to
/// `positions_m`; nothing when there is none. `hits` is scratch.
std::optional<NearSurface> near_surface(const Eigen::Vector3d& touching_point_m, double margin_m, const SurfaceBvh& bvh,
                                        const Eigen::VectorXd& positions_m, const SurfaceMesh& surface,
                                        const CorotationalElasticity& elasticity,
                                        std::vector<SurfaceBvh::SphereHit>& hits);

}  // namespace tissue
