// SurfaceViews (see surface_views.hpp).
#include "core/surface_views.hpp"

#include "core/parameter_error.hpp"

#include <algorithm>
#include <span>

namespace tissue {

namespace {

Eigen::VectorXd rest_positions(const DeformableBody& body) {
  Eigen::VectorXd positions_m;
  body.positions(Eigen::VectorXd::Zero(body.dof_count()), positions_m);
  return positions_m;
}

std::unique_ptr<CutRenderSurface> embedded(const TetMesh& mesh, const TriangleSurface* surface) {
  if (surface == nullptr) return nullptr;
  try {
    return std::make_unique<CutRenderSurface>(mesh, *surface, default_max_outside_m(mesh), surface->source_name);
  } catch (const MeshError& error) {
    throw ParameterError(error.what());
  }
}

}  // namespace

SurfaceViews::SurfaceViews(const DeformableBody& body, bool with_bvh, const TriangleSurface* render_surface)
    : m_surface(extract_surface(body.mesh())),
      m_vertex_positions_m(rest_positions(body)),
      m_positions_m(m_vertex_positions_m),
      m_cut_surface(body.mesh().vertex_count()),
      m_bvh(with_bvh ? m_surface.triangles : std::vector<std::array<int, 3>>{}, m_positions_m,
            [this] { bring_positions_up_to_date(); }),
      m_render(embedded(body.mesh(), render_surface)) {}

void SurfaceViews::update_positions(const DeformableBody& body, const Eigen::VectorXd& displacement_m) {
  m_render_mapped = false;
  m_positions_body = &body;
  m_positions_displacement_m = &displacement_m;
  m_drawn_current = false;
}

void SurfaceViews::bring_positions_up_to_date() const {
  if (m_positions_body == nullptr) return;
  const DeformableBody& body = *m_positions_body;
  const Eigen::VectorXd& displacement_m = *m_positions_displacement_m;
  m_positions_body = nullptr;
  m_positions_displacement_m = nullptr;
  body.positions(displacement_m, m_vertex_positions_m);
  m_positions_m.head(m_vertex_positions_m.size()) = m_vertex_positions_m;
  m_cut_surface.update_points(body, displacement_m, m_positions_m);
}

void SurfaceViews::bring_drawn_up_to_date(const DeformableBody& body, const Eigen::VectorXd& displacement_m) const {
  if (m_drawn_current) return;
  bring_positions_up_to_date();
  const int points = m_cut_surface.point_count();
  m_cut_surface.update_drawn(body, m_surface, displacement_m, m_positions_m);
  // Points the drawn lists added (split triangles' centres) get their positions.
  if (m_cut_surface.point_count() != points) m_cut_surface.update_points(body, displacement_m, m_positions_m);
  m_drawn_current = true;
}

void SurfaceViews::add_cut_tets(const DeformableBody& body, const Eigen::VectorXd& displacement_m, int first_cut_tet) {
  const int new_faces = m_cut_surface.add_cut_tets(body, first_cut_tet, m_surface);
  update_positions(body, displacement_m);
  const auto& faces = m_cut_surface.triangles();
  m_bvh.add_triangles(std::span(faces).last(static_cast<size_t>(new_faces)));
  // The faces of the cut tets these replaced are out of the tree: no query needs a zero-area face,
  // and their corners are no longer updated.
  std::vector<int> retired = m_cut_surface.take_retired_faces();
  for (int& face : retired) face += first_cut_face_id();
  m_bvh.remove_triangles(retired);
}

int SurfaceViews::first_cut_face_id() const {
  // The cut faces are the tree's last triangles; without a BVH of the surface, all of them.
  return m_bvh.unfitted().triangle_count() - static_cast<int>(m_cut_surface.triangles().size());
}

void SurfaceViews::take_out_parked(const DeformableBody& body) {
  const int first_cut_face = first_cut_face_id();
  std::vector<int> ids;
  for (int t = 0; t < first_cut_face; ++t) {  // the mesh's surface triangles (when the BVH has them)
    const std::array<int, 3>& triangle = m_surface.triangles[static_cast<size_t>(t)];
    const bool parked = std::all_of(triangle.begin(), triangle.end(), [&](int v) {
      const int row = body.dofs().vertex_row[static_cast<size_t>(v)];
      return row >= 0 && body.parked(row);
    });
    if (parked) ids.push_back(t);
  }
  const auto first_face = ids.size();
  m_cut_surface.parked_faces(body, ids);
  for (auto k = first_face; k < ids.size(); ++k) ids[k] += first_cut_face;
  m_bvh.remove_triangles(ids);
}

const CutRenderSurface* SurfaceViews::render_surface(const DeformableBody& body,
                                                     const Eigen::VectorXd& displacement_m) const {
  if (!m_render) return nullptr;
  if (m_render_cut_tets != body.cut_tets().size()) {
    m_render->rebuild(body);
    m_render_cut_tets = body.cut_tets().size();
    m_render_mapped = false;
  }
  if (!m_render_mapped) {
    m_render->update(body, displacement_m);
    m_render_mapped = true;
  }
  return m_render.get();
}

}  // namespace tissue
