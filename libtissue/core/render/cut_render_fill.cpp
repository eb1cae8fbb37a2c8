// CutRenderSurface: the holes filled by their cuts' faces (cut_render_detail::peel_by_cuts) are kept
// where their material part then encloses its simulated volume, or where they bound the solid they
// close as drawn (cut_render_detail::fills_bounding_solids; cut_render_surface.hpp); the others are
// peeled again in other orders (cut_render_detail::peel_again).
#include "core/render/cut_render_surface.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <vector>

namespace tissue {

namespace cut_render_detail {

double winding_number(const std::vector<std::array<int, 3>>& triangles, const std::vector<size_t>& shell,
                      const std::vector<Eigen::Vector3d>& x, const Eigen::Vector3d& point) {
  double solid_angles = 0.0;
  for (const size_t t : shell) {
    const std::array<int, 3>& corners = triangles[t];
    const Eigen::Vector3d a = x[static_cast<size_t>(corners[0])] - point;
    const Eigen::Vector3d b = x[static_cast<size_t>(corners[1])] - point;
    const Eigen::Vector3d c = x[static_cast<size_t>(corners[2])] - point;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    solid_angles += 2.0 * std::atan2(a.dot(b.cross(c)), denominator);
  }
  return solid_angles / (4.0 * std::numbers::pi);
}

std::vector<char> fills_bounding_solids(const std::vector<std::array<int, 3>>& triangles,
                                        const std::vector<Eigen::Vector3d>& x,
                                        const std::vector<std::pair<size_t, size_t>>& fills) {
  std::vector<int> root, size;
  point_shells(triangles, x.size(), root, size);
  std::vector<int> shell_index(x.size(), -1);  // by root point: the shells that hold a probe, numbered
  const auto shell_of = [&](int point) -> int& {
    return shell_index[static_cast<size_t>(root[static_cast<size_t>(point)])];
  };
  // The probes: each fill's largest triangles; the shells they lie on, listed.
  struct Probe {
    size_t fill;
    Eigen::Vector3d centroid, normal;
    int shell;
  };
  std::vector<Probe> probes;
  int shells = 0;
  for (size_t f = 0; f < fills.size(); ++f) {
    // (the norm of its doubled area, its normal times that, the triangle), the largest first
    std::vector<std::tuple<double, Eigen::Vector3d, size_t>> by_area;
    for (size_t t = fills[f].first; t < fills[f].second; ++t) {
      const std::array<int, 3>& c = triangles[t];
      const Eigen::Vector3d& a = x[static_cast<size_t>(c[0])];
      const Eigen::Vector3d normal = (x[static_cast<size_t>(c[1])] - a).cross(x[static_cast<size_t>(c[2])] - a);
      by_area.emplace_back(normal.norm(), normal, t);
    }
    const size_t count = std::min(FILL_PROBES, by_area.size());
    std::partial_sort(by_area.begin(), by_area.begin() + static_cast<long>(count), by_area.end(),
                      [](const auto& s, const auto& t) { return std::get<0>(s) > std::get<0>(t); });
    for (size_t k = 0; k < count; ++k) {
      const auto& [area, normal, t] = by_area[k];
      if (!(area > 0.0)) continue;  // a flat triangle bounds nothing and hides nothing
      const std::array<int, 3>& c = triangles[t];
      const Eigen::Vector3d centroid =
          (x[static_cast<size_t>(c[0])] + x[static_cast<size_t>(c[1])] + x[static_cast<size_t>(c[2])]) / 3.0;
      int& shell = shell_of(c[0]);
      if (shell < 0) shell = shells++;
      probes.push_back({f, centroid, normal.normalized(), shell});
    }
  }
  std::vector<std::vector<size_t>> shell_triangles(static_cast<size_t>(shells));
  for (size_t t = 0; t < triangles.size(); ++t) {
    const int shell = shell_of(triangles[t][0]);
    if (shell >= 0) shell_triangles[static_cast<size_t>(shell)].push_back(t);
  }
  std::vector<char> sound(fills.size(), 1);
  for (const Probe& probe : probes) {
    const std::vector<size_t>& shell = shell_triangles[static_cast<size_t>(probe.shell)];
    const double in_front = winding_number(triangles, shell, x, probe.centroid + FILL_PROBE_OFFSET_M * probe.normal);
    const double behind = winding_number(triangles, shell, x, probe.centroid - FILL_PROBE_OFFSET_M * probe.normal);
    const long front = std::lround(in_front), back = std::lround(behind);
    const bool boundary = front == 0 && back == 1;  // the solid's face, outward
    const bool hidden = front >= 1 && back >= 1;    // within the solid: no one sees it
    if (!boundary && !hidden) sound[probe.fill] = 0;
  }
  return sound;
}

void drop_fills(std::vector<std::array<int, 3>>& triangles, const std::vector<std::pair<size_t, size_t>>& fills,
                const std::vector<char>& keep) {
  std::vector<char> drop(triangles.size(), 0);
  for (size_t f = 0; f < fills.size(); ++f) {
    if (keep[f] != 0) continue;
    std::fill(drop.begin() + static_cast<long>(fills[f].first), drop.begin() + static_cast<long>(fills[f].second), 1);
  }
  size_t kept = 0;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (drop[t] == 0) triangles[kept++] = triangles[t];
  }
  triangles.resize(kept);
}

int peel_again(std::vector<std::vector<int>> loops, std::vector<std::array<int, 3>>& triangles, size_t first_cap,
               const std::vector<Eigen::Vector3d>& x, CapEdges& edges, const std::function<int(int)>& cut_of,
               const std::function<std::vector<int>(int, int)>& line_points) {
  for (const PeelOrder order : PEEL_AGAIN_ORDERS) {
    if (loops.empty()) break;
    edges.caps.clear();  // the caps kept so far: the dropped faces' edges are free again
    for (size_t t = first_cap; t < triangles.size(); ++t) edges.add(triangles[t]);
    std::vector<std::pair<size_t, size_t>> fills;
    std::vector<size_t> fill_loop;
    for (size_t l = 0; l < loops.size(); ++l) {
      std::vector<std::vector<int>> faces;
      if (!peel_by_cuts(loops[l], x, cut_of, line_points, faces, order)) continue;
      const size_t first = triangles.size();
      for (const std::vector<int>& face : faces) cap_polygon(face, x, triangles, edges);
      fills.emplace_back(first, triangles.size());
      fill_loop.push_back(l);
    }
    if (fills.empty()) continue;
    const std::vector<char> sound = fills_bounding_solids(triangles, x, fills);
    std::vector<char> open(loops.size(), 1);
    for (size_t f = 0; f < fills.size(); ++f) {
      if (sound[f] != 0) open[fill_loop[f]] = 0;
    }
    drop_fills(triangles, fills, sound);
    size_t kept = 0;
    for (size_t l = 0; l < loops.size(); ++l) {
      if (open[l] != 0) loops[kept++] = std::move(loops[l]);
    }
    loops.resize(kept);
  }
  return static_cast<int>(loops.size());
}

}  // namespace cut_render_detail

namespace {

double enclosed_m3(const std::vector<Eigen::Vector3d>& x, const std::array<int, 3>& t) {
  return x[static_cast<size_t>(t[0])].dot(x[static_cast<size_t>(t[1])].cross(x[static_cast<size_t>(t[2])])) / 6.0;
}

}  // namespace

std::vector<size_t> CutRenderSurface::drop_unsound_fills(const DeformableBody& body,
                                                         const std::vector<FilledHole>& filled,
                                                         const std::vector<int>& open_parts) {
  if (filled.empty()) return {};
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
  // The fills the volume refuses, then those of them that do not bound their solid as drawn either
  // (the winding numbers only where needed: a shell of the organ's surface is 80k triangles).
  std::vector<std::pair<size_t, size_t>> refused;
  std::vector<size_t> refused_hole;  // its index in `filled`
  for (size_t h = 0; h < filled.size(); ++h) {
    const FilledHole& hole = filled[h];
    const auto part = static_cast<size_t>(hole.part);
    const double ratio = render_m3[part] / (r0 * simulated_m3[part]);
    const bool open = std::find(open_parts.begin(), open_parts.end(), hole.part) != open_parts.end();
    if (open || std::abs(ratio - 1.0) > FILLED_PART_VOLUME_TOLERANCE) {
      refused.emplace_back(hole.first_triangle, hole.end_triangle);
      refused_hole.push_back(h);
    }
  }
  if (refused.empty()) return {};
  const std::vector<char> bounding = cut_render_detail::fills_bounding_solids(m_triangles, m_rest_m, refused);
  std::vector<size_t> dropped;
  for (size_t h = 0; h < refused.size(); ++h) {
    if (bounding[h] == 0) dropped.push_back(refused_hole[h]);
  }
  cut_render_detail::drop_fills(m_triangles, refused, bounding);
  return dropped;
}

}  // namespace tissue
