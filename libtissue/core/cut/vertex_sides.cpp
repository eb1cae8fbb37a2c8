// The vertices' sides of the blade (issue 41; see volume_cutter.hpp): the blade's plane, when the
// blade passes a vertex, the cut around a vertex it did not pass, and a tet's cut from its
// vertices' sides. Member functions of VolumeCutter, apart from the search.
#include "core/cut/volume_cutter.hpp"

#include "core/collide/geometry.hpp"
#include "core/cut/cut_geometry.hpp"
#include "core/index_cast.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tissue {
bool VolumeCutter::continues_plane(const Blade& previous, const Blade& current) const {
  if (m_cut_id < 0 || !m_plane.valid) return false;
  const Eigen::Vector3d motion = 0.5 * ((current.tip_m - previous.tip_m) + (current.handle_m - previous.handle_m));
  const Eigen::Vector3d normal = (current.handle_m - current.tip_m).cross(motion);
  const double norm = normal.norm();
  // And in it: a parallel stroke beside the last one is another stroke.
  const double off_plane_m = std::abs((current.tip_m - m_plane.tip_m).dot(m_plane.normal));
  return norm > 0.0 && std::abs(normal.dot(m_plane.normal)) >= SAME_STROKE_COSINE * norm &&
         off_plane_m <= SAME_STROKE_OFFSET_M;
}

void VolumeCutter::update_plane(const Blade& previous, const Blade& current, bool new_session) {
  const Eigen::Vector3d middle = 0.5 * (current.tip_m + current.handle_m);
  if (new_session) {
    m_last_stroke_normal = m_plane.valid ? m_plane.normal : Eigen::Vector3d::Zero();
    m_plane = BladePlane{};
    m_turn_rad = 0.0;
    m_plane.anchor_m = 0.5 * (previous.tip_m + previous.handle_m);
  }
  m_plane.tip_m = current.tip_m;
  m_plane.blade_m = current.handle_m - current.tip_m;
  const Eigen::Vector3d motion = middle - m_plane.anchor_m;
  const double motion_m = motion.norm();
  if (!(motion_m > 0.0) || (m_plane.valid && motion_m < BLADE_PLANE_BASELINE_M)) return;
  Eigen::Vector3d normal = m_plane.blade_m.cross(motion);
  // A blade moving along itself (a plunge) keeps the plane it had.
  if (!(normal.norm() > BLADE_PLANE_SINE_FLOOR * m_plane.blade_m.norm() * motion_m)) return;
  normal.normalize();
  if (m_plane.valid && normal.dot(m_plane.normal) < 0.0) normal = -normal;  // one "above" for the session
  if (m_plane.valid) m_turn_rad += std::acos(std::clamp(normal.dot(m_plane.normal), -1.0, 1.0));
  Eigen::Vector3d ahead = normal.cross(m_plane.blade_m).normalized();
  if (ahead.dot(motion) < 0.0) ahead = -ahead;
  m_plane.normal = normal;
  m_plane.ahead = ahead;
  m_plane.valid = true;
  if (motion_m >= BLADE_PLANE_BASELINE_M) m_plane.anchor_m = middle;
}

VolumeCutter::PlaneOffset VolumeCutter::plane_offset(int vertex, const Eigen::VectorXd& positions_m) const {
  const Eigen::Vector3d offset = vertex_position(positions_m, vertex) - m_plane.tip_m;
  return PlaneOffset{offset.dot(m_plane.blade_m) / m_plane.blade_m.squaredNorm(), offset.dot(m_plane.ahead),
                     offset.dot(m_plane.normal)};
}

void VolumeCutter::decide_if_passed(int vertex, const Eigen::VectorXd& positions_m) {
  // Once per passage: a vertex decided by the blade that comes back to it after turning through half
  // a turn or more (the next turn of a spiral) is decided again, for the tets of that turn.
  if (!m_plane.valid || decided_now(vertex)) return;
  const PlaneOffset o = plane_offset(vertex, positions_m);
  if (!o.within_span()) return;
  if (o.ahead_m > 0.0) {
    if (m_watched_flag[to_size(vertex)] == 0) {
      m_watched_flag[to_size(vertex)] = 1;
      m_watched.push_back(vertex);
    }
  } else if (o.ahead_m >= m_strip_back_m - m_vertex_reach_m[to_size(vertex)]) {
    // In this step's strip, or behind it by less than an edge (a tet the sweep enters that reaches
    // back off the plane). Not one far behind: a piece swinging on its last bridge carries
    // vertices the blade passed long ago, off its plane, back into its path.
    record_side(vertex, o.distance_m);
  }
}

// A vertex on the blade counts above in every tet around it: a tet that touches the sweep only
// there, its other vertices below, is cut, though the search, which goes from tet to tet where the
// sweep crosses, need not visit it. Its other vertices are decided (or watched) as if it had been.
void VolumeCutter::decide_around_vertices_on_blade(const Eigen::VectorXd& positions_m) {
  while (!m_on_blade.empty()) {
    const int vertex = m_on_blade.back();
    m_on_blade.pop_back();
    const int end = m_adjacency.vertex_tets_begin[to_size(vertex) + 1];
    for (int k = m_adjacency.vertex_tets_begin[to_size(vertex)]; k < end; ++k) {
      for (const int v : m_mesh.tets[to_size(m_adjacency.vertex_tets[to_size(k)])]) decide_if_passed(v, positions_m);
    }
  }
}

void VolumeCutter::pass_watched(const Eigen::VectorXd& positions_m) {
  std::size_t kept = 0;
  for (const int vertex : m_watched) {
    if (decided_now(vertex)) {
      m_watched_flag[to_size(vertex)] = 0;
      continue;
    }
    const PlaneOffset o = plane_offset(vertex, positions_m);
    if (o.within_span() && o.ahead_m <= 0.0) {
      record_side(vertex, o.distance_m);
      m_watched_flag[to_size(vertex)] = 0;
      continue;
    }
    m_watched[kept++] = vertex;
  }
  m_watched.resize(kept);
}

void VolumeCutter::record_side(int vertex, double distance_m) {
  const double snap_m = m_vertex_snap_m[to_size(vertex)];
  if (!side_decided(vertex)) m_session_vertices.push_back(vertex);  // once (a later passage decides again)
  m_vertex_session[to_size(vertex)] = m_cut_id;
  m_vertex_distance_m[to_size(vertex)] = distance_m;
  m_vertex_turn_rad[to_size(vertex)] = m_turn_rad;
  m_vertex_side[to_size(vertex)] =
      distance_m > snap_m ? std::int8_t{1} : (distance_m < -snap_m ? std::int8_t{-1} : std::int8_t{0});
  m_new_vertices.push_back(vertex);
  if (m_vertex_side[to_size(vertex)] == 0) m_on_blade.push_back(vertex);
}

bool VolumeCutter::has_both_sides_passed(int tet) const {
  bool below = false;
  bool above = false;
  for (const int v : m_mesh.tets[to_size(tet)]) {
    if (!decided_now(v) || m_fitted_close[to_size(v)] == m_close_count) continue;
    below |= m_vertex_side[to_size(v)] < 0;
    above |= m_vertex_side[to_size(v)] >= 0;
  }
  return below && above && one_passage(tet);
}

bool VolumeCutter::stopped_in(int tet) const {
  bool passed = false;
  for (const int v : m_mesh.tets[to_size(tet)]) {
    if (!decided_now(v)) {
      if (m_watched_flag[to_size(v)] == 0) return false;
    } else if (m_fitted_close[to_size(v)] != m_close_count) {
      passed = true;
    }
  }
  return passed;
}

bool VolumeCutter::one_passage(int tet) const {
  double first_rad = std::numeric_limits<double>::infinity();
  double last_rad = -first_rad;
  for (const int v : m_mesh.tets[to_size(tet)]) {
    if (!decided_now(v)) continue;
    first_rad = std::min(first_rad, m_vertex_turn_rad[to_size(v)]);
    last_rad = std::max(last_rad, m_vertex_turn_rad[to_size(v)]);
  }
  return last_rad - first_rad <= 0.5 * PASSAGE_TURN_RAD;
}

// When the stroke ends (the blade left the body, or the scalpel was taken away inside it), two kinds
// of tet would hold the sides together, and their vertices the blade did not pass are decided by
// the cut around them, the linear fit over the rest positions of the decided vertices next to them
// of their distances from the blade, repeated until no such tet is left:
//  * a tet the blade went into and stopped in: it passed some of its vertices and saw the others
//    ahead of it, within its span (watched). So a stroke ends at the far faces of the tets it reached:
//    one that ends at an earlier cut (a T junction) or at another stroke's start (a flap's corner)
//    cuts the tets up to it (the virtual node algorithm's resolution: a crack ends at a tet's face);
//  * a tet with vertices the blade passed on both sides whose other vertices it never passed (a
//    piece that swung about its last bridge while the blade cut it, carrying them off the blade's
//    path). Vertices the closing decided do not count: the cut does not creep on from them.
// Vertices below the tip are never seen within the span: a blade that does not reach through the
// body cuts only the tets it passed whole.
void VolumeCutter::close_session(CutStepReport& report, const Eigen::VectorXd& positions_m) {
  if (!m_plane.valid) return;
  ++m_close_count;  // the vertices this closing decides by the fit do not make a tet two-sided
  for (int round = 0; round < MAX_CLOSING_ROUNDS; ++round) {
    ++m_stamp;
    m_closing.clear();
    for (const int vertex : m_session_vertices) {
      const int end = m_adjacency.vertex_tets_begin[to_size(vertex) + 1];
      for (int k = m_adjacency.vertex_tets_begin[to_size(vertex)]; k < end; ++k) {
        const int tet = m_adjacency.vertex_tets[to_size(k)];
        if (m_tet_stamp[to_size(tet)] == m_stamp || cut_now(tet)) continue;
        m_tet_stamp[to_size(tet)] = m_stamp;
        const bool stopped = stopped_in(tet);
        const bool both_sides = has_both_sides_passed(tet);
        if (!stopped && !both_sides) continue;
        for (const int v : m_mesh.tets[to_size(tet)]) {
          if (decided_now(v)) continue;
          if (stopped) {
            m_closing.push_back(v);
            continue;
          }
          // Only where the blade went: between tip and handle, not more than an edge ahead of where
          // it stopped (a tet it crossed whole whose vertex lies ahead, off its plane).
          const PlaneOffset o = plane_offset(v, positions_m);
          if (both_sides && o.within_span() && o.ahead_m <= m_vertex_reach_m[to_size(v)]) m_closing.push_back(v);
        }
      }
    }
    m_on_blade.clear();  // a closing decides by the fit, not by the blade: no star to go on to
    if (m_closing.empty()) return;
    for (const int vertex : m_closing) {
      if (!decided_now(vertex)) decide_from_neighbours(vertex, positions_m);
    }
    ++m_stamp;
    cut_around_new_vertices(report);
  }
}

void VolumeCutter::decide_from_neighbours(int vertex, const Eigen::VectorXd& positions_m) {
  const Eigen::Vector3d& x = m_mesh.rest_positions_m[to_size(vertex)];
  const int begin = m_adjacency.vertex_tets_begin[to_size(vertex)];
  const int end = m_adjacency.vertex_tets_begin[to_size(vertex) + 1];
  double reach_m = 0.0;  // the rest positions are scaled by the star's size: a fit of order one
  for (int k = begin; k < end; ++k) {
    for (const int w : m_mesh.tets[to_size(m_adjacency.vertex_tets[to_size(k)])]) {
      reach_m = std::max(reach_m, (m_mesh.rest_positions_m[to_size(w)] - x).norm());
    }
  }
  Eigen::Matrix4d normal_matrix = Eigen::Matrix4d::Zero();
  Eigen::Vector4d right = Eigen::Vector4d::Zero();
  for (int k = begin; k < end; ++k) {
    for (const int w : m_mesh.tets[to_size(m_adjacency.vertex_tets[to_size(k)])]) {
      if (w == vertex || !decided_now(w)) continue;
      Eigen::Vector4d row;
      row << (m_mesh.rest_positions_m[to_size(w)] - x) / reach_m, 1.0;
      normal_matrix += row * row.transpose();
      right += row * m_vertex_distance_m[to_size(w)];
    }
  }
  // The fit's value at the vertex itself, in the material: where the body now carries the vertex
  // does not matter. Neighbours that do not determine a fit (too few, or near one plane) leave the
  // vertex's distance from the blade now.
  Eigen::FullPivLU<Eigen::Matrix4d> fit(normal_matrix);
  fit.setThreshold(FIT_PIVOT_FLOOR);
  record_side(vertex, reach_m > 0.0 && fit.rank() == 4 ? fit.solve(right)[3] : plane_offset(vertex, positions_m).distance_m);
  m_fitted_close[to_size(vertex)] = m_close_count;
}

std::optional<TetCut> VolumeCutter::cut_of(int tet, double end_margin) const {
  const Tet& vertices = m_mesh.tets[to_size(tet)];
  // The vertices' states: +1, -1, or 0 on the blade (within the snap distance when decided).
  std::array<std::int8_t, 4> state{};
  int below = 0;
  for (std::size_t j = 0; j < 4; ++j) {
    if (!decided_now(vertices[j])) return std::nullopt;
    state[j] = m_vertex_side[to_size(vertices[j])];
    below += state[j] < 0 ? 1 : 0;
  }
  if (!one_passage(tet)) return std::nullopt;  // its vertices decided by different turns
  // A vertex on the blade goes above, in every tet, so that each vertex has one side: a tet is cut
  // when some vertex lies below and some above or on the blade (a blade that touches the tet only
  // at vertices, an edge or a face from above does not cut it).
  if (below == 0 || below == 4) return std::nullopt;
  std::array<std::int8_t, 4> side{};
  for (std::size_t j = 0; j < 4; ++j) side[j] = state[j] < 0 ? std::int8_t{-1} : std::int8_t{1};
  // Where each edge between the sides is cut, one value per edge shared by every tet around it:
  // where the sweep crossed it in this session, else between its ends' distances from the blade
  // when they were decided (an edge whose end the body carried across the blade and back).
  std::array<double, 6> ratio{};
  for (std::size_t k = 0; k < 6; ++k) {
    const std::size_t i = to_size(TET_EDGES[k][0]);
    const std::size_t j = to_size(TET_EDGES[k][1]);
    if (side[i] == side[j]) continue;
    const int edge = m_adjacency.tet_edges[to_size(tet)][k];
    const auto& ends = m_adjacency.edges[to_size(edge)];
    double r = 0.0;  // along {v0, v1}
    if (crossed_now(edge)) {
      r = m_edge_ratio[to_size(edge)];
    } else {
      const double d0 = m_vertex_distance_m[to_size(ends[0])];
      const double d1 = m_vertex_distance_m[to_size(ends[1])];
      r = d0 / (d0 - d1);
    }
    // Stored along {v0, v1} with v0 < v1; the tet's local edge may run the other way.
    ratio[k] = vertices[i] == ends[0] ? r : 1.0 - r;
  }
  TetCut cut = cut_from_sides(m_mesh.rest_corners(tet), side, ratio, end_margin, m_settings.min_volume_fraction);

  cut.tet = tet;
  cut.cut_id = m_cut_id;
  cut.min_volume_fraction = m_settings.min_volume_fraction;
  cut.blade_normal = m_plane.valid ? m_plane.normal : m_last_stroke_normal;
  return cut;
}

}  // namespace tissue
