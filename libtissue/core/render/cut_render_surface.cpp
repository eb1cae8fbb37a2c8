// CutRenderSurface: the re-mesh's sequence (rebuild) and the mapping of its points to nodes; finding
// the points' cells is in cut_render_locate.cpp, splitting in cut_render_split.cpp, caps in
// cut_render_caps.cpp.
#include "core/render/cut_render_surface.hpp"

#include "core/render/cut_render_detail.hpp"
#include "core/system/resident_reserve.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <numeric>
#include <utility>

namespace tissue {

using cut_render_detail::edge_key;

CutRenderSurface::CutRenderSurface(const TetMesh& mesh, TriangleSurface surface, double max_outside_m,
                                   const std::string& source_name)
    : m_mesh(mesh),
      m_surface(std::move(surface)),
      m_embedding(embed_surface(m_mesh, m_surface, max_outside_m, source_name)) {
  // Room for the split and cap points (and the triangles they make) of a session's cuts, written
  // now: the first cut's split points re-allocated the per-point arrays of the organ's 41k-point
  // surface inside its slot (docs/BENCHMARKS.md). Past the room they grow as before.
  const size_t vertices = m_surface.vertices_m.size(), surface_triangles = m_surface.triangles.size();
  const size_t points = vertices + vertices / SPLIT_POINT_ROOM_DIVISOR;
  const size_t triangles = surface_triangles + surface_triangles / SPLIT_POINT_ROOM_DIVISOR;
  reserve_resident(m_points, points);
  reserve_resident(m_rest_m, points);
  reserve_resident(m_point_cut, points);
  reserve_resident(m_point_nodes, points);
  reserve_resident(m_positions_m, points);
  reserve_resident(m_normals, points);
  reserve_resident(m_triangles, triangles);
  reserve_resident(m_dirty, vertices);
  reserve_resident(m_part, vertices);
  reserve_resident(m_uncut_part, vertices);
  reserve_resident(m_vertex_part, vertices);
  reserve_resident(m_skin, triangles);
  reserve_resident(m_next_skin, triangles);
  reserve_resident(m_skin_first, surface_triangles + 1);
  reserve_resident(m_next_skin_first, surface_triangles + 1);
  reserve_resident(m_bubbles.parent, points);
  reserve_resident(m_bubbles.size, points);
  reserve_resident(m_bubbles.state, points);
  reserve_resident(m_bubbles.volume_m3, points);
  reserve_resident(m_bubbles.shell_of, triangles);
  for (const SurfaceEmbedding& e : m_embedding) m_points.push_back(Point{e.tet, e.weights, -1, -1});
  m_rest_m = m_surface.vertices_m;
  m_triangles = m_surface.triangles;
  m_vertex_triangles_first.assign(m_surface.vertices_m.size() + 1, 0);
  for (const auto& triangle : m_surface.triangles) {
    for (const int v : triangle) ++m_vertex_triangles_first[static_cast<size_t>(v) + 1];
  }
  std::partial_sum(m_vertex_triangles_first.begin(), m_vertex_triangles_first.end(), m_vertex_triangles_first.begin());
  m_vertex_triangles.resize(3 * m_surface.triangles.size());
  std::vector<int> fill(m_vertex_triangles_first.begin(), m_vertex_triangles_first.end() - 1);
  for (size_t t = 0; t < m_surface.triangles.size(); ++t) {
    for (const int v : m_surface.triangles[t])
      m_vertex_triangles[static_cast<size_t>(fill[static_cast<size_t>(v)]++)] = static_cast<int>(t);
  }
  for (const auto& triangle : m_surface.triangles) {
    for (size_t k = 0; k < 3; ++k) m_surface_edges.insert(edge_key(triangle[k], triangle[(k + 1) % 3]));
  }
}

void CutRenderSurface::rebuild(const DeformableBody& body) {
  m_normals_current = false;  // the triangles change
  find_material_parts(body);
  const size_t vertices = m_surface.vertices_m.size();
  const auto tet_count = static_cast<size_t>(m_mesh.tet_count());
  std::vector<char>& dirty = m_dirty;
  std::vector<int>& part = m_part;
  dirty.assign(vertices, 1);
  part.assign(vertices, -1);
  const bool scratch = mark_dirty_points(body, dirty, part);
  m_from_scratch = scratch;
  const size_t old_split_points = m_split_points;
  if (scratch) {
    std::fill(dirty.begin(), dirty.end(), 1);
    m_splits.clear();
    m_points.resize(vertices);
    m_rest_m.resize(vertices);
    m_point_cut.assign(vertices, -1);
    m_cut_edges = 0;
    m_orphan_points = 0;
    m_skin.clear();
    m_skin_first.assign(m_surface.triangles.size() + 1, 0);
  } else {
    m_points.resize(m_split_points);  // the last caps' points go: the caps are made again
    m_rest_m.resize(m_split_points);
    m_point_cut.resize(m_split_points);
  }
  relocate_points(body, dirty, part);
  m_vertex_part = part;
  m_part_ids = m_copy_root.size();
  m_tet_cut.resize(tet_count);
  for (size_t t = 0; t < tet_count; ++t) m_tet_cut[t] = body.cut_tet_index(static_cast<int>(t));
  if (!scratch) drop_moved_splits(dirty);
  split_skin(body, dirty, part);
  const size_t first_new = scratch ? 0 : old_split_points;
  m_split_points = m_points.size();
  m_triangles = m_skin;
  cap_loops(body);
  map_points_to_nodes(first_new, dirty);
}

void CutRenderSurface::map_points_to_nodes(size_t first_new, const std::vector<char>& dirty_vertices) {
  // The slot of each (cut tet, piece) in use, by cut tet and piece. An incremental re-mesh keeps the
  // slots (a piece no point rides on any more keeps its slot until the next re-mesh from scratch) and
  // maps only the points it moved or added.
  int cut_tets = 0, pieces = 1;
  for (const Point& point : m_points) {
    cut_tets = std::max(cut_tets, point.cut_tet + 1);
    pieces = std::max(pieces, point.piece + 1);
  }
  const bool all = m_from_scratch || static_cast<size_t>(pieces) > m_slot_stride;
  if (all) {
    m_slot_stride = std::max(static_cast<size_t>(pieces), MIN_SLOT_STRIDE);
    m_slot_of.clear();
    m_slots.clear();
  }
  m_slot_of.resize(std::max(m_slot_of.size(), static_cast<size_t>(cut_tets) * m_slot_stride), -1);
  m_point_nodes.resize(m_points.size());
  const auto map = [&](size_t i) {
    const Point& point = m_points[i];
    std::array<int, 4>& nodes = m_point_nodes[i];
    if (point.cut_tet < 0) {
      for (size_t j = 0; j < 4; ++j) nodes[j] = m_mesh.tets[static_cast<size_t>(point.tet)][j];
      return;
    }
    int& slot = m_slot_of[static_cast<size_t>(point.cut_tet) * m_slot_stride + static_cast<size_t>(point.piece)];
    if (slot < 0) {
      slot = static_cast<int>(m_slots.size());
      m_slots.push_back({point.cut_tet, point.piece});
    }
    for (size_t j = 0; j < 4; ++j) nodes[j] = m_mesh.vertex_count() + 4 * slot + static_cast<int>(j);
  };
  if (all) {
    for (size_t i = 0; i < m_points.size(); ++i) map(i);
    return;
  }
  for (size_t v = 0; v < dirty_vertices.size(); ++v) {
    if (dirty_vertices[v] != 0) map(v);
  }
  for (size_t i = first_new; i < m_points.size(); ++i) map(i);
}

void CutRenderSurface::node_positions(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                                      std::vector<Eigen::Vector3d>& nodes_m) const {
  body.positions(displacement_m, m_real_positions_m);
  nodes_m.resize(static_cast<size_t>(node_count()));
  for (int v = 0; v < m_mesh.vertex_count(); ++v)
    nodes_m[static_cast<size_t>(v)] = m_real_positions_m.segment<3>(3 * v);
  for (size_t s = 0; s < m_slots.size(); ++s) {
    const TetPositions corners = body.piece_positions(displacement_m, m_slots[s][0], m_slots[s][1]);
    for (size_t j = 0; j < 4; ++j) nodes_m[static_cast<size_t>(m_mesh.vertex_count()) + 4 * s + j] = corners[j];
  }
}

void CutRenderSurface::update(const DeformableBody& body, const Eigen::VectorXd& displacement_m) {
  node_positions(body, displacement_m, m_node_positions_m);
  m_positions_m.resize(m_points.size());
  for (size_t i = 0; i < m_points.size(); ++i) {
    const Eigen::Vector4d& weights = m_points[i].weights;
    const std::array<int, 4>& nodes = m_point_nodes[i];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (size_t k = 0; k < 4; ++k)
      x += weights(static_cast<Eigen::Index>(k)) * m_node_positions_m[static_cast<size_t>(nodes[k])];
    m_positions_m[i] = x;
  }
  m_normals_current = false;
}

const std::vector<Eigen::Vector3d>& CutRenderSurface::normals() const {
  if (!m_normals_current) {
    vertex_normals(m_positions_m, m_triangles, m_normals);
    m_normals_current = true;
  }
  return m_normals;
}

}  // namespace tissue
