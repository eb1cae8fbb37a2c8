// SurfaceViews: the tissue's surfaces at the current state, each for its reader. The mesh's surface
// and the faces the cuts opened, at the current positions (3 per mesh vertex, then the cut faces'
// corners, written when first read after a step: a step nothing reads them after pays nothing for
// them); the surface BVH over both, refitted when a query needs it (contact, cutting); the
// triangles to draw (the tet skin); and the finer render surface riding on the tets, re-meshed and
// mapped only when asked for.
#pragma once

#include "core/collide/lazy_surface_bvh.hpp"
#include "core/cut/cut_surface.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/mesh/topology.hpp"
#include "core/render/cut_render_surface.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

namespace tissue {

class SurfaceViews {
 public:
  /// At the rest state of `body`; a BVH over the surface only `with_bvh` (contact or cutting on);
  /// `render_surface` (or none) embedded in the tets. Throws ParameterError for a render surface
  /// that cannot be embedded.
  SurfaceViews(const DeformableBody& body, bool with_bvh, const TriangleSurface* render_surface);
  SurfaceViews(const SurfaceViews&) = delete;
  SurfaceViews& operator=(const SurfaceViews&) = delete;

  /// The positions are now those at `displacement_m`: written when first read (positions_m(), the
  /// BVH's queries, the drawn surface), from `body` and `displacement_m` as they are then, so both
  /// must outlive the views and change only with a call of this again (the Tissue's body and state).
  /// The BVH is marked stale by moved(), not here.
  void update_positions(const DeformableBody& body, const Eigen::VectorXd& displacement_m);
  /// The positions moved: the BVH refits at its next query.
  void moved() { m_bvh.positions_moved(); }
  /// The cut tets from `first_cut_tet` on were just made: their opened faces join the surface and
  /// the BVH, at `displacement_m` (both parts still coincide).
  void add_cut_tets(const DeformableBody& body, const Eigen::VectorXd& displacement_m, int first_cut_tet);
  /// Parts of `body` were parked (out of the field, out of the dynamics): their faces leave the BVH
  /// (the mesh's surface triangles whose three vertices are parked, the cut faces of parked pieces),
  /// so that the blade's and the probe's queries and the refits before them no longer pay for them.
  /// They are still drawn.
  void take_out_parked(const DeformableBody& body);

  [[nodiscard]] const SurfaceMesh& surface() const { return m_surface; }
  [[nodiscard]] const CutSurface& cut_surface() const { return m_cut_surface; }
  /// The mesh vertices (3 each), then the corners of the cut faces.
  [[nodiscard]] const Eigen::VectorXd& positions_m() const {
    bring_positions_up_to_date();
    return m_positions_m;
  }
  [[nodiscard]] const LazySurfaceBvh& bvh() const { return m_bvh; }
  [[nodiscard]] int mesh_triangle_count() const { return static_cast<int>(m_surface.triangles.size()); }

  /// The render surface at `displacement_m`, re-meshed for the cuts made since it was last asked for
  /// and mapped when the state changed; nullptr when the scene has none.
  [[nodiscard]] const CutRenderSurface* render_surface(const DeformableBody& body,
                                                       const Eigen::VectorXd& displacement_m) const;

  [[nodiscard]] bool has_render_surface() const { return m_render != nullptr; }

  /// The surface to draw at `displacement_m` (the state of the last update_positions()), with
  /// corners indexing positions_m(): the mesh's surface without the triangles of cut tets, their
  /// pieces either side of the cut (the skin), then the cut faces. Its lists are made when read, for
  /// the cuts and positions since they were last read: a step pays nothing for a tet skin that is
  /// not drawn (a scene that draws its render surface).
  template <class Visit>
  void for_each_drawn_triangle(const DeformableBody& body, const Eigen::VectorXd& displacement_m, Visit&& visit) const;
  [[nodiscard]] std::size_t drawn_triangle_count(const DeformableBody& body,
                                                 const Eigen::VectorXd& displacement_m) const {
    bring_drawn_up_to_date(body, displacement_m);
    return m_surface.triangles.size() - m_cut_surface.replaced_triangles().size() +
           m_cut_surface.skin_triangles().size() + m_cut_surface.drawn_triangles().size();
  }
  /// The cut faces of the surface to draw (the last part of for_each_drawn_triangle()'s).
  [[nodiscard]] const std::vector<std::array<int, 3>>& drawn_cut_triangles(
      const DeformableBody& body, const Eigen::VectorXd& displacement_m) const {
    bring_drawn_up_to_date(body, displacement_m);
    return m_cut_surface.drawn_triangles();
  }

 private:
  // The BVH id of the first cut face (cut face t is this + t).
  [[nodiscard]] int first_cut_face_id() const;
  void bring_drawn_up_to_date(const DeformableBody& body, const Eigen::VectorXd& displacement_m) const;
  // Writes the positions update_positions() left to their first read.
  void bring_positions_up_to_date() const;

  SurfaceMesh m_surface;
  mutable Eigen::VectorXd m_vertex_positions_m;
  // The positions and the cut faces; their drawn lists (and the points those add) are brought up to
  // date by the readers of the drawn surface (bring_drawn_up_to_date).
  mutable Eigen::VectorXd m_positions_m;
  // Set by update_positions() until the positions are written (nullptr: they are current).
  mutable const DeformableBody* m_positions_body = nullptr;
  mutable const Eigen::VectorXd* m_positions_displacement_m = nullptr;
  mutable CutSurface m_cut_surface;
  mutable bool m_drawn_current = true;
  LazySurfaceBvh m_bvh;
  // The render surface, brought up to date by render_surface() (re-meshed when the cut tets changed,
  // mapped when the state changed).
  mutable std::unique_ptr<CutRenderSurface> m_render;
  mutable std::optional<std::size_t> m_render_cut_tets;  // the cut tets it was meshed for (none: not yet)
  mutable bool m_render_mapped = false;
};

template <class Visit>
void SurfaceViews::for_each_drawn_triangle(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                                           Visit&& visit) const {
  bring_drawn_up_to_date(body, displacement_m);
  const std::vector<int>& replaced = m_cut_surface.replaced_triangles();  // ascending
  auto next_replaced = replaced.begin();
  for (std::size_t t = 0; t < m_surface.triangles.size(); ++t) {
    if (next_replaced != replaced.end() && *next_replaced == static_cast<int>(t)) {
      ++next_replaced;
      continue;
    }
    visit(m_surface.triangles[t]);
  }
  for (const auto& triangle : m_cut_surface.skin_triangles()) visit(triangle);
  for (const auto& triangle : m_cut_surface.drawn_triangles()) visit(triangle);
}

}  // namespace tissue
