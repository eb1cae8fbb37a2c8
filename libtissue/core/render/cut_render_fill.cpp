// CutRenderSurface: the holes filled by their cuts' faces (cut_render_detail::peel_by_cuts) are kept
// only where their material part then encloses its simulated volume (cut_render_surface.hpp).
#include "core/render/cut_render_surface.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tissue {

namespace {

double enclosed_m3(const std::vector<Eigen::Vector3d>& x, const std::array<int, 3>& t) {
  return x[static_cast<size_t>(t[0])].dot(x[static_cast<size_t>(t[1])].cross(x[static_cast<size_t>(t[2])])) / 6.0;
}

}  // namespace

int CutRenderSurface::drop_unsound_fills(const DeformableBody& body, const std::vector<FilledHole>& filled,
                                         const std::vector<int>& open_parts) {
  if (filled.empty()) return 0;
  // The uncut render surface encloses r0 times the tets' volume (it bulges out of their flat faces).
  double surface_m3 = 0.0, tets_m3 = 0.0;
  for (const auto& t : m_surface.triangles) surface_m3 += enclosed_m3(m_surface.vertices_m, t);
  // Each material part's simulated volume: its uncut tets' and its pieces'.
  std::vector<double> simulated_m3(m_copy_root.size(), 0.0), render_m3(m_copy_root.size(), 0.0);
  for (int t = 0; t < m_mesh.tet_count(); ++t) {
    const auto x = m_mesh.rest_corners(t);
    const double volume_m3 = std::abs(signed_tet_volume(x[0], x[1], x[2], x[3]));
    tets_m3 += volume_m3;
    const int k = body.cut_tet_index(t);
    const int pieces = k < 0 ? 1 : static_cast<int>(body.xfem().piece_count(k));
    for (int p = 0; p < pieces; ++p) {
      const double fraction = k < 0 ? 1.0 : body.xfem().piece(k, p).weight;
      simulated_m3[static_cast<size_t>(m_copy_root[static_cast<size_t>(copy_of(body, t, k, p, 0))])] +=
          fraction * volume_m3;
    }
  }
  const double r0 = surface_m3 / tets_m3;
  for (const auto& t : m_triangles) {
    render_m3[static_cast<size_t>(part_of(body, m_points[static_cast<size_t>(t[0])]))] += enclosed_m3(m_rest_m, t);
  }
  std::vector<char> drop(m_triangles.size(), 0);
  int reopened = 0;
  for (const FilledHole& hole : filled) {
    const auto part = static_cast<size_t>(hole.part);
    const double ratio = render_m3[part] / (r0 * simulated_m3[part]);
    const bool open = std::find(open_parts.begin(), open_parts.end(), hole.part) != open_parts.end();
    if (!open && std::abs(ratio - 1.0) <= FILLED_PART_VOLUME_TOLERANCE) continue;
    for (size_t t = hole.first_triangle; t < hole.end_triangle; ++t) drop[t] = 1;
    ++reopened;
  }
  size_t kept = 0;
  for (size_t t = 0; t < m_triangles.size(); ++t) {
    if (drop[t] == 0) m_triangles[kept++] = m_triangles[t];
  }
  m_triangles.resize(kept);
  return reopened;
}

}  // namespace tissue
