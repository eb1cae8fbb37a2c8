// CutRenderSurface: which cell (tet, and piece of a cut tet) each surface point rides on, the
// material parts the cells make, which points a re-mesh must locate again, and the points the caps
// add (on lines between two points, riding on the cell of the nearer).
#include "core/render/cut_render_surface.hpp"

#include "core/fem/piece_outside.hpp"
#include "core/fem/union_find.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace tissue {

CutRenderSurface::Point CutRenderSurface::locate(const DeformableBody& body, int tet,
                                                 const Eigen::Vector3d& rest_m) const {
  Point point{tet, barycentric_weights(m_mesh.rest_corners(tet), rest_m), body.cut_tet_index(tet), -1};
  if (point.cut_tet < 0) return point;
  const CutTetGeometry& geometry = body.cut_geometry(point.cut_tet);
  double best = std::numeric_limits<double>::infinity();
  for (size_t q = 0; q < geometry.pieces.size(); ++q) {
    const double outside = outside_piece_m(geometry, q, rest_m);
    if (outside < best) {
      best = outside;
      point.piece = static_cast<int>(q);
    }
  }
  return point;
}

void CutRenderSurface::find_material_parts(const DeformableBody& body) {
  // Union-find over the copies of the vertices (real: the vertex id; ghost: vertex count + its row;
  // held copy: after the rows), joined within each cell.
  const int vertex_count = m_mesh.vertex_count();
  m_copy_root.resize(static_cast<size_t>(vertex_count) + static_cast<size_t>(body.dof_count() / 3) +
                     body.held_copies().size());
  std::iota(m_copy_root.begin(), m_copy_root.end(), 0);
  const auto find = [&](int i) { return find_root(m_copy_root, i); };
  for (int t = 0; t < m_mesh.tet_count(); ++t) {
    const int k = body.cut_tet_index(t);
    const int pieces = k < 0 ? 1 : static_cast<int>(body.xfem().piece_count(k));
    for (int p = 0; p < pieces; ++p) {
      const int first = find(copy_of(body, t, k, p, 0));
      for (size_t j = 1; j < 4; ++j) m_copy_root[static_cast<size_t>(find(copy_of(body, t, k, p, j)))] = first;
    }
  }
  for (size_t i = 0; i < m_copy_root.size(); ++i) m_copy_root[i] = find(static_cast<int>(i));
}

int CutRenderSurface::copy_of(const DeformableBody& body, int tet, int cut_tet, int piece, size_t j) const {
  const int vertex = m_mesh.tets[static_cast<size_t>(tet)][j];
  if (cut_tet < 0) return vertex;
  const int row = body.xfem().piece(cut_tet, piece).ghost_row[j];
  if (row == -1) return vertex;
  return m_mesh.vertex_count() + (row >= 0 ? row : body.dof_count() / 3 + held_copy_index(row));
}

int CutRenderSurface::part_of(const DeformableBody& body, const Point& point) const {
  return m_copy_root[static_cast<size_t>(copy_of(body, point.tet, point.cut_tet, point.piece, 0))];
}

// Incremental: only what rides on a tet whose cut changed since the last re-mesh, or on one of its
// face neighbours (whose cut planes an edge's split may use), is located and split again; every
// other edge keeps its split points and every other triangle its pieces. Where the material parts
// regrouped (a piece came free, or two joined), an edge between two unchanged points whose ends went
// from one part to two (or back) is split again too: such an edge is split by its ends' parts where
// no piece tells them apart. From scratch the first time and when dropped split points pile up.
bool CutRenderSurface::mark_dirty_points(const DeformableBody& body, std::vector<char>& dirty,
                                         std::vector<int>& part) const {
  const size_t vertices = m_surface.vertices_m.size();
  const auto tet_count = static_cast<size_t>(m_mesh.tet_count());
  if (m_tet_cut.size() != tet_count || m_orphan_points > static_cast<int>(vertices) / 4) return true;
  std::vector<char> dirty_tet(tet_count, 0);
  for (size_t t = 0; t < tet_count; ++t) {
    if (body.cut_tet_index(static_cast<int>(t)) == m_tet_cut[t]) continue;
    dirty_tet[t] = 1;
    for (const int n : body.adjacency().face_neighbor[t]) {
      if (n >= 0) dirty_tet[static_cast<size_t>(n)] = 1;
    }
  }
  // Whether the unchanged points' parts group them as before (old and new part ids in one-to-one
  // correspondence over them); if not, the edges between them that went from one part to two (or
  // back) are split again.
  std::vector<int> old_to_new(m_part_ids, -1), new_to_old(m_copy_root.size(), -1);
  bool regrouped = false;
  for (size_t v = 0; v < vertices; ++v) {
    dirty[v] = dirty_tet[static_cast<size_t>(m_embedding[v].tet)];
    if (dirty[v] != 0) continue;
    part[v] = part_of(body, m_points[v]);
    int& to_new = old_to_new[static_cast<size_t>(m_vertex_part[v])];
    int& to_old = new_to_old[static_cast<size_t>(part[v])];
    if (to_new < 0) to_new = part[v];
    if (to_old < 0) to_old = m_vertex_part[v];
    regrouped = regrouped || to_new != part[v] || to_old != m_vertex_part[v];
  }
  for (size_t t = 0; regrouped && t < m_surface.triangles.size(); ++t) {
    const auto& triangle = m_surface.triangles[t];
    for (size_t k = 0; k < 3; ++k) {
      const auto u = static_cast<size_t>(triangle[k]), w = static_cast<size_t>(triangle[(k + 1) % 3]);
      if (dirty[u] != 0 || dirty[w] != 0) continue;  // split again anyway
      if ((m_vertex_part[u] == m_vertex_part[w]) != (part[u] == part[w])) dirty[u] = dirty[w] = 1;
    }
  }
  return false;
}

// Locates the dirty surface vertices again (their cells) and gives them their material parts.
void CutRenderSurface::relocate_points(const DeformableBody& body, const std::vector<char>& dirty,
                                       std::vector<int>& part) {
  const size_t vertices = m_surface.vertices_m.size();
  const auto locate_vertex = [&](size_t v) {
    const SurfaceEmbedding& e = m_embedding[v];
    m_points[v] =
        body.cut_tet_index(e.tet) < 0 ? Point{e.tet, e.weights, -1, -1} : locate(body, e.tet, m_surface.vertices_m[v]);
  };
  for (size_t v = 0; v < vertices; ++v) {
    if (dirty[v] != 0) {
      locate_vertex(v);
      part[v] = part_of(body, m_points[v]);
    }
  }
}

int CutRenderSurface::add_point_like(int model, const Eigen::Vector3d& rest_m) {
  const Point& like = m_points[static_cast<size_t>(model)];
  m_points.push_back(
      Point{like.tet, barycentric_weights(m_mesh.rest_corners(like.tet), rest_m), like.cut_tet, like.piece});
  m_rest_m.push_back(rest_m);
  m_point_cut.push_back(-1);
  return static_cast<int>(m_points.size()) - 1;
}

std::vector<int> CutRenderSurface::line_points(int from, int to) {
  // Interior points about JOIN_SPACING_M apart on the straight rest segment; each half rides on the
  // cell of its nearer end (exact under that piece's rigid motion).
  constexpr double JOIN_SPACING_M = 0.0015;
  const Eigen::Vector3d a = m_rest_m[static_cast<size_t>(from)];
  const Eigen::Vector3d b = m_rest_m[static_cast<size_t>(to)];
  // At least one point: the line must not coincide with an edge the skin may already have.
  const int segments = std::max(2, static_cast<int>(std::ceil((b - a).norm() / JOIN_SPACING_M)));
  std::vector<int> points;
  for (int k = 1; k < segments; ++k) {
    const double s = static_cast<double>(k) / segments;
    points.push_back(add_point_like(s < 0.5 ? from : to, a + s * (b - a)));
  }
  return points;
}

}  // namespace tissue
