// near_surface (see surface_near.hpp).
#include "core/contact/surface_near.hpp"

#include "core/contact/contact_stiffness.hpp"
#include "core/contact/surface_point.hpp"

namespace tissue {

std::optional<NearSurface> near_surface(const Eigen::Vector3d& touching_point_m, double margin_m, const SurfaceBvh& bvh,
                                        const Eigen::VectorXd& positions_m, const SurfaceMesh& surface,
                                        const CorotationalElasticity& elasticity,
                                        std::vector<SurfaceBvh::SphereHit>& hits) {
  if (!(margin_m > 0.0)) return std::nullopt;
  bvh.intersect_sphere(touching_point_m, margin_m, positions_m, hits);
  const auto mesh_triangles = static_cast<int>(surface.triangles.size());
  for (const SurfaceBvh::SphereHit& hit : hits) {  // nearest first
    if (hit.triangle >= mesh_triangles) continue;  // a cut face: the probe touches the mesh's surface only
    const std::array<int, 3>& triangle = surface.triangles[static_cast<std::size_t>(hit.triangle)];
    const Eigen::Vector3d area_normal = triangle_area_normal(triangle, positions_m);
    const double twice_area = area_normal.norm();
    if (!(twice_area > 0.0)) continue;  // a degenerate (crushed) triangle has no normal
    NearSurface near;
    for (std::size_t k = 0; k < 3; ++k) {
      near.point_m += hit.barycentric[static_cast<Eigen::Index>(k)] * positions_m.segment<3>(3 * triangle[k]);
    }
    near.normal = area_normal / twice_area;
    near.stiffness_n_per_m = element_local_contact_stiffness(elasticity, surface, hit.triangle);
    near.distance_m = hit.distance_m;
    return near;
  }
  return std::nullopt;
}

}  // namespace tissue
