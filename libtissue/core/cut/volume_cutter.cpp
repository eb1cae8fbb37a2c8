// Volume collision detection for cutting (see volume_cutter.hpp; dissertation 4.3.2).
#include "core/cut/volume_cutter.hpp"

#include "core/collide/geometry.hpp"
#include "core/cut/cut_geometry.hpp"
#include "core/material/material.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <stdexcept>
#include <sstream>
#include <string>

namespace tissue {
namespace {

std::size_t at(int index) { return static_cast<std::size_t>(index); }

Eigen::Vector3d vertex_position(const Eigen::VectorXd& positions_m, int vertex) {
  return positions_m.segment<3>(3 * static_cast<Eigen::Index>(vertex));
}

bool is_finite(const Blade& blade) { return blade.tip_m.allFinite() && blade.handle_m.allFinite(); }

/// True when the closed segment a-b meets the tet x: an end inside, or a face crossed (algorithm 4's test).
bool segment_touches_tet(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::array<Eigen::Vector3d, 4>& x) {
  for (const Eigen::Vector3d* end : {&a, &b}) {
    const auto barycentric = tet_barycentric(*end, x[0], x[1], x[2], x[3]);
    if (barycentric && barycentric->minCoeff() >= 0.0) return true;
  }
  for (const auto& face : TET_FACES) {
    if (intersect_segment_triangle(a, b, x[at(face[0])], x[at(face[1])], x[at(face[2])])) return true;
  }
  return false;
}

}  // namespace

Blade swept_from(const Blade& previous, const Blade& current) {
  return Blade{previous.tip_m - SWEEP_BACK_OVERLAP * (current.tip_m - previous.tip_m),
               previous.handle_m - SWEEP_BACK_OVERLAP * (current.handle_m - previous.handle_m)};
}

/// The surface the blade sweeps between two steps, approximated by two triangles (algorithm 5's
/// MakeSurface), wound alike: (tip0, handle0, tip1) and (handle0, handle1, tip1). "Above" is the
/// side their normals point to, e.g. (handle0 - tip0) x (tip1 - tip0).
struct VolumeCutter::Sweep {
  std::array<std::array<Eigen::Vector3d, 3>, 2> triangles;
  std::array<Eigen::Vector3d, 2> normals;
  /// The sweep's boundary: both blade positions, the tip's path and the handle's path.
  std::array<std::array<Eigen::Vector3d, 2>, 4> boundary;
  Eigen::Vector3d lower;  ///< bounding box
  Eigen::Vector3d upper;

  Sweep(const Blade& previous, const Blade& current)
      : triangles{{{previous.tip_m, previous.handle_m, current.tip_m},
                   {previous.handle_m, current.handle_m, current.tip_m}}},
        boundary{{{previous.tip_m, previous.handle_m},
                  {current.tip_m, current.handle_m},
                  {previous.tip_m, current.tip_m},
                  {previous.handle_m, current.handle_m}}} {
    for (std::size_t m = 0; m < 2; ++m) {
      normals[m] = (triangles[m][1] - triangles[m][0]).cross(triangles[m][2] - triangles[m][0]);
    }
    lower = previous.tip_m.cwiseMin(previous.handle_m).cwiseMin(current.tip_m).cwiseMin(current.handle_m);
    upper = previous.tip_m.cwiseMax(previous.handle_m).cwiseMax(current.tip_m).cwiseMax(current.handle_m);
  }

  struct EdgeCrossing {
    double ratio = 0.0;         ///< along a -> b, in [0, 1]
    std::int8_t upper_end = 0;  ///< +1: b above, -1: a above, 0: unknown
  };
  /// Where the edge a-b (lengthened by EDGE_ROUND_OFF_EXTENSION) crosses the sweep; the first triangle wins
  /// when it crosses both.
  [[nodiscard]] std::optional<EdgeCrossing> cross_edge(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    const Eigen::Vector3d direction = b - a;
    const Eigen::Vector3d from = a - EDGE_ROUND_OFF_EXTENSION * direction;
    const Eigen::Vector3d to = b + EDGE_ROUND_OFF_EXTENSION * direction;
    for (std::size_t m = 0; m < 2; ++m) {
      const auto hit = intersect_segment_triangle(from, to, triangles[m][0], triangles[m][1], triangles[m][2]);
      if (!hit) continue;
      const double ratio = std::clamp(
          hit->segment_parameter * (1.0 + 2.0 * EDGE_ROUND_OFF_EXTENSION) - EDGE_ROUND_OFF_EXTENSION, 0.0, 1.0);
      const double lift = direction.dot(normals[m]);
      return EdgeCrossing{ratio, static_cast<std::int8_t>(lift > 0.0 ? 1 : (lift < 0.0 ? -1 : 0))};
    }
    return std::nullopt;
  }
  /// True when the sweep's boundary crosses the triangle (t0, t1, t2).
  [[nodiscard]] bool boundary_crosses(const Eigen::Vector3d& t0, const Eigen::Vector3d& t1,
                                      const Eigen::Vector3d& t2) const {
    for (const auto& segment : boundary) {
      if (intersect_segment_triangle(segment[0], segment[1], t0, t1, t2)) return true;
    }
    return false;
  }
  /// True when the sweep and the triangle (t0, t1, t2) intersect: an edge of one crosses the other.
  [[nodiscard]] bool crosses_triangle(const Eigen::Vector3d& t0, const Eigen::Vector3d& t1,
                                      const Eigen::Vector3d& t2) const {
    // Quick rejection: a triangle strictly on one side of both sweep triangles' planes meets neither.
    if (strictly_one_side(0, t0, t1, t2) && strictly_one_side(1, t0, t1, t2)) return false;
    return cross_edge(t0, t1) || cross_edge(t1, t2) || cross_edge(t2, t0) || boundary_crosses(t0, t1, t2);
  }
  [[nodiscard]] bool strictly_one_side(std::size_t m, const Eigen::Vector3d& t0, const Eigen::Vector3d& t1,
                                       const Eigen::Vector3d& t2) const {
    const double d0 = (t0 - triangles[m][0]).dot(normals[m]);
    const double d1 = (t1 - triangles[m][0]).dot(normals[m]);
    const double d2 = (t2 - triangles[m][0]).dot(normals[m]);
    return (d0 > 0.0 && d1 > 0.0 && d2 > 0.0) || (d0 < 0.0 && d1 < 0.0 && d2 < 0.0);
  }
};

void validate(const CutterSettings& settings) {
  if (!(settings.vertex_snap_fraction >= 0.0 && settings.vertex_snap_fraction < 0.5)) {
    throw ParameterError("cutter: vertex snap fraction must be in [0, 0.5), got " +
                         std::to_string(settings.vertex_snap_fraction));
  }
  if (!(settings.min_volume_fraction >= SMALLEST_MIN_VOLUME_FRACTION && settings.min_volume_fraction < 0.5)) {
    std::ostringstream message;
    message << "cutter: minimum volume fraction must be in [" << SMALLEST_MIN_VOLUME_FRACTION << ", 0.5), got "
            << settings.min_volume_fraction;
    throw ParameterError(message.str());
  }
}

VolumeCutter::VolumeCutter(const TetMesh& mesh, const TetAdjacency& adjacency, const SurfaceMesh& surface,
                           CutterSettings settings)
    : m_mesh(mesh), m_adjacency(adjacency), m_surface(surface), m_settings(settings) {
  tissue::validate(settings);
  const std::size_t tets = mesh.tets.size();
  const std::size_t edges = adjacency.edges.size();
  if (adjacency.face_neighbor.size() != tets || adjacency.tet_edges.size() != tets ||
      adjacency.edge_tets_begin.size() != edges + 1 || surface.triangle_tet.size() != surface.triangles.size()) {
    throw std::invalid_argument("VolumeCutter: adjacency or surface does not belong to the mesh (" +
                                std::to_string(tets) + " tets, " + std::to_string(edges) + " edges)");
  }
  m_tet_stamp.assign(tets, 0);
  m_candidate_stamp.assign(tets, 0);
  m_tet_cut_session.assign(tets, -1);
  m_tet_ignored_session.assign(tets, -1);
  m_tet_cut_count.assign(tets, 0);
  m_edge_stamp.assign(edges, 0);
  m_edge_session.assign(edges, -1);
  m_edge_ratio.assign(edges, 0.0);
  m_edge_upper_end.assign(edges, 0);
  // Each tet (edge) enters a list at most once per step: these capacities are never exceeded.
  m_active.reserve(tets);
  m_visited.reserve(tets);
  m_stack.reserve(tets);
  m_candidates.reserve(tets);
  m_new_cuts.reserve(tets);
  m_new_edges.reserve(edges);
  m_seeds.reserve(surface.triangles.size());
  // The BVH also holds the cut faces added later: room for as many again.
  m_hits.reserve(2 * surface.triangles.size());
  m_box_triangles.reserve(2 * surface.triangles.size());
}

std::optional<double> VolumeCutter::edge_crossing(int edge) const {
  if (m_cut_id < 0 || m_edge_session[at(edge)] != m_cut_id) return std::nullopt;
  return m_edge_ratio[at(edge)];
}

void VolumeCutter::end_cut() {
  m_cutting = false;
  m_active.clear();
}

void VolumeCutter::save(SessionState& state) const {
  state.cutting = m_cutting;
  state.cut_id = m_cut_id;
  state.tet_cut_session = m_tet_cut_session;
  state.tet_ignored_session = m_tet_ignored_session;
  state.tet_cut_count = m_tet_cut_count;
  state.edge_session = m_edge_session;
  state.edge_ratio = m_edge_ratio;
  state.edge_upper_end = m_edge_upper_end;
  state.active = m_active;
}

void VolumeCutter::restore(const SessionState& state) {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("VolumeCutter::restore: " + what); };
  const size_t tets = m_tet_cut_session.size();
  const size_t edges = m_edge_session.size();
  if (state.tet_cut_session.size() != tets || state.tet_ignored_session.size() != tets ||
      state.tet_cut_count.size() != tets ||
      state.edge_session.size() != edges || state.edge_ratio.size() != edges || state.edge_upper_end.size() != edges) {
    fail("the state is of another mesh (" + std::to_string(state.tet_cut_session.size()) + " tets, " +
         std::to_string(state.edge_session.size()) + " edges; this one has " + std::to_string(tets) + " and " +
         std::to_string(edges) + ")");
  }
  if (state.cut_id < -1 || (state.cutting && state.cut_id < 0)) fail("bad session id " + std::to_string(state.cut_id));
  const auto session_ok = [&](int session) { return session >= -1 && session <= state.cut_id; };
  if (!std::all_of(state.tet_cut_session.begin(), state.tet_cut_session.end(), session_ok) ||
      !std::all_of(state.tet_ignored_session.begin(), state.tet_ignored_session.end(), session_ok) ||
      !std::all_of(state.edge_session.begin(), state.edge_session.end(), session_ok)) {
    fail("a tet or edge names a session after " + std::to_string(state.cut_id));
  }
  if (!std::all_of(state.tet_cut_count.begin(), state.tet_cut_count.end(),
                   [](std::int8_t count) { return count >= 0 && count <= MAX_PIECE_CUTS; })) {
    fail("a tet's cut count is outside [0, " + std::to_string(MAX_PIECE_CUTS) + "]");
  }
  if (!std::all_of(state.active.begin(), state.active.end(),
                   [&](int tet) { return tet >= 0 && static_cast<size_t>(tet) < tets; })) {
    fail("an active tet is out of range");
  }
  if (state.active.size() > tets) fail("more active tets than the mesh has");
  m_cutting = state.cutting;
  m_cut_id = state.cut_id;
  std::copy(state.tet_cut_session.begin(), state.tet_cut_session.end(), m_tet_cut_session.begin());
  std::copy(state.tet_ignored_session.begin(), state.tet_ignored_session.end(), m_tet_ignored_session.begin());
  std::copy(state.tet_cut_count.begin(), state.tet_cut_count.end(), m_tet_cut_count.begin());
  std::copy(state.edge_session.begin(), state.edge_session.end(), m_edge_session.begin());
  std::copy(state.edge_ratio.begin(), state.edge_ratio.end(), m_edge_ratio.begin());
  std::copy(state.edge_upper_end.begin(), state.edge_upper_end.end(), m_edge_upper_end.begin());
  m_active.assign(state.active.begin(), state.active.end());
}

void VolumeCutter::validate(const Blade& previous, const Blade& current, const Eigen::VectorXd& positions_m,
                            const SurfaceBvh& bvh) const {
  if (!is_finite(previous) || !is_finite(current)) {
    throw std::invalid_argument("VolumeCutter::step: blade position is not finite");
  }
  if (positions_m.size() < 3 * static_cast<Eigen::Index>(m_mesh.vertex_count())) {
    throw std::invalid_argument("VolumeCutter::step: " + std::to_string(positions_m.size()) + " position entries for " +
                                std::to_string(m_mesh.vertex_count()) + " vertices");
  }
  if (!positions_m.allFinite()) throw std::invalid_argument("VolumeCutter::step: a vertex position is not finite");
  if (bvh.triangle_count() < static_cast<int>(m_surface.triangles.size())) {
    throw std::invalid_argument("VolumeCutter::step: the BVH has fewer triangles than the surface");
  }
}

CutStepReport VolumeCutter::step(const Blade& previous, const Blade& current, const Eigen::VectorXd& positions_m,
                                 const SurfaceBvh& bvh) {
  validate(previous, current, positions_m, bvh);
  const auto start = std::chrono::steady_clock::now();
  m_new_cuts.clear();
  m_visited.clear();
  m_new_edges.clear();
  m_candidates.clear();
  m_seeds.clear();
  CutStepReport report;
  const Sweep sweep(swept_from(previous, current), current);
  const bool was_cutting = m_cutting;
  if (!was_cutting) {
    // Algorithm 5, first part: the blade (or, added, its sweep) meets the surface.
    ++m_stamp;
    find_initial_tets(current, positions_m, bvh);
    ++m_stamp;
    collect_surface_seeds(sweep, positions_m, bvh);
    if (m_active.empty() && m_seeds.empty()) {
      report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return report;
    }
    m_cutting = true;
    ++m_cut_id;
  } else {
    ++m_stamp;
  }
  // Algorithm 2 from every active tet, then from where the sweep crosses the surface elsewhere.
  for (const int tet : m_active) search_from(tet, sweep, positions_m);
  if (was_cutting) collect_surface_seeds(sweep, positions_m, bvh);
  for (const int tet : m_seeds) search_from(tet, sweep, positions_m);

  find_next_active(current, positions_m);
  complete_touched_tets(report);
  if (m_active.empty()) m_cutting = false;

  report.cutting = m_cutting;
  report.cut_id = m_cut_id;
  report.intersected_tets = static_cast<int>(m_visited.size());
  report.active_tets = static_cast<int>(m_active.size());
  report.new_edge_crossings = static_cast<int>(m_new_edges.size());
  report.newly_cut_tets = static_cast<int>(m_new_cuts.size());
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

// Algorithm 1 (FindInitTet), iteratively: from the tets of the surface triangles the blade
// crosses, over the faces it crosses. Every entry point is used, not only the first, so that a
// blade through a non-convex body finds each piece of itself inside.
void VolumeCutter::find_initial_tets(const Blade& blade, const Eigen::VectorXd& positions_m, const SurfaceBvh& bvh) {
  m_active.clear();
  bvh.intersect_segment(blade.tip_m, blade.handle_m, positions_m, m_hits);
  const int surface_triangles = static_cast<int>(m_surface.triangles.size());
  for (const auto& hit : m_hits) {
    if (hit.triangle < 0 || hit.triangle >= surface_triangles) continue;  // a cut face
    const int entry = m_surface.triangle_tet[at(hit.triangle)];
    if (m_tet_stamp[at(entry)] == m_stamp) continue;
    m_tet_stamp[at(entry)] = m_stamp;
    m_stack.push_back(entry);
    while (!m_stack.empty()) {
      const int tet = m_stack.back();
      m_stack.pop_back();
      m_active.push_back(tet);
      const Tet& vertices = m_mesh.tets[at(tet)];
      for (std::size_t k = 0; k < 4; ++k) {
        const int next = m_adjacency.face_neighbor[at(tet)][k];
        if (next < 0 || m_tet_stamp[at(next)] == m_stamp) continue;
        const auto& face = TET_FACES[k];
        if (intersect_segment_triangle(blade.tip_m, blade.handle_m, vertex_position(positions_m, vertices[at(face[0])]),
                                       vertex_position(positions_m, vertices[at(face[1])]),
                                       vertex_position(positions_m, vertices[at(face[2])]))) {
          m_tet_stamp[at(next)] = m_stamp;
          m_stack.push_back(next);
        }
      }
    }
  }
}

// Added seeds: the tets of surface triangles the sweep crosses and the search has not reached.
void VolumeCutter::collect_surface_seeds(const Sweep& sweep, const Eigen::VectorXd& positions_m,
                                         const SurfaceBvh& bvh) {
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(1e-9 * (sweep.upper - sweep.lower).norm());
  bvh.overlap_box(sweep.lower - pad, sweep.upper + pad, m_box_triangles);
  const int surface_triangles = static_cast<int>(m_surface.triangles.size());
  for (const int triangle : m_box_triangles) {
    if (triangle < 0 || triangle >= surface_triangles) continue;  // a cut face
    const int tet = m_surface.triangle_tet[at(triangle)];
    if (m_tet_stamp[at(tet)] == m_stamp) continue;
    const auto& vertices = m_surface.triangles[at(triangle)];
    if (sweep.crosses_triangle(vertex_position(positions_m, vertices[0]), vertex_position(positions_m, vertices[1]),
                               vertex_position(positions_m, vertices[2]))) {
      m_seeds.push_back(tet);
    }
  }
}

void VolumeCutter::push_unvisited(int tet) {
  if (m_tet_stamp[at(tet)] == m_stamp) return;
  m_tet_stamp[at(tet)] = m_stamp;  // algorithm 2's isVisited
  m_visited.push_back(tet);
  m_stack.push_back(tet);
}

// Algorithm 2 (FindInterTet), iteratively with an explicit stack.
void VolumeCutter::search_from(int seed, const Sweep& sweep, const Eigen::VectorXd& positions_m) {
  push_unvisited(seed);
  while (!m_stack.empty()) {
    const int tet = m_stack.back();
    m_stack.pop_back();
    visit(tet, sweep, positions_m);
  }
}

void VolumeCutter::visit(int tet, const Sweep& sweep, const Eigen::VectorXd& positions_m) {
  for (const int edge : m_adjacency.tet_edges[at(tet)]) process_edge(edge, sweep, positions_m);
  // Added: step across faces the sweep's boundary crosses (no edge need be crossed there).
  const Tet& vertices = m_mesh.tets[at(tet)];
  for (std::size_t k = 0; k < 4; ++k) {
    const int next = m_adjacency.face_neighbor[at(tet)][k];
    if (next < 0 || m_tet_stamp[at(next)] == m_stamp) continue;
    const auto& face = TET_FACES[k];
    if (sweep.boundary_crosses(vertex_position(positions_m, vertices[at(face[0])]),
                               vertex_position(positions_m, vertices[at(face[1])]),
                               vertex_position(positions_m, vertices[at(face[2])]))) {
      push_unvisited(next);
    }
  }
}

// Each edge is tested once per step; a crossed edge is recorded once per session (algorithm 3:
// the first crossing wins) and the tets around it are searched next.
void VolumeCutter::process_edge(int edge, const Sweep& sweep, const Eigen::VectorXd& positions_m) {
  if (m_edge_stamp[at(edge)] == m_stamp) return;
  m_edge_stamp[at(edge)] = m_stamp;
  const auto& ends = m_adjacency.edges[at(edge)];
  const auto crossing = sweep.cross_edge(vertex_position(positions_m, ends[0]), vertex_position(positions_m, ends[1]));
  if (!crossing) return;
  if (m_edge_session[at(edge)] != m_cut_id) {
    m_edge_session[at(edge)] = m_cut_id;
    m_edge_ratio[at(edge)] = crossing->ratio;
    m_edge_upper_end[at(edge)] = crossing->upper_end;
    m_new_edges.push_back(edge);
  }
  const int end = m_adjacency.edge_tets_begin[at(edge) + 1];
  for (int k = m_adjacency.edge_tets_begin[at(edge)]; k < end; ++k) push_unvisited(m_adjacency.edge_tets[at(k)]);
}

// Algorithm 4: the searched tets that the blade still touches (an end inside counts, so the
// handle may be inside the body).
void VolumeCutter::find_next_active(const Blade& blade, const Eigen::VectorXd& positions_m) {
  m_active.clear();
  for (const int tet : m_visited) {
    const Tet& vertices = m_mesh.tets[at(tet)];
    const std::array<Eigen::Vector3d, 4> x = {
        vertex_position(positions_m, vertices[0]), vertex_position(positions_m, vertices[1]),
        vertex_position(positions_m, vertices[2]), vertex_position(positions_m, vertices[3])};
    if (segment_touches_tet(blade.tip_m, blade.handle_m, x)) m_active.push_back(tet);
  }
}

// A tet can only become completely cut when one of its edges gets a crossing: test the tets
// around this step's new crossings.
void VolumeCutter::complete_touched_tets(CutStepReport& report) {
  for (const int edge : m_new_edges) {
    const int end = m_adjacency.edge_tets_begin[at(edge) + 1];
    for (int k = m_adjacency.edge_tets_begin[at(edge)]; k < end; ++k) {
      const int tet = m_adjacency.edge_tets[at(k)];
      if (m_candidate_stamp[at(tet)] == m_stamp) continue;
      m_candidate_stamp[at(tet)] = m_stamp;
      m_candidates.push_back(tet);
    }
  }
  for (const int tet : m_candidates) {
    if (m_tet_cut_session[at(tet)] == m_cut_id) continue;
    const Tet& vertices = m_mesh.tets[at(tet)];
    TetEdgeCrossings crossings;
    for (std::size_t k = 0; k < 6; ++k) {
      const int edge = m_adjacency.tet_edges[at(tet)][k];
      if (m_edge_session[at(edge)] != m_cut_id) continue;
      // Stored along {v0, v1} with v0 < v1; the tet's local edge may run the other way.
      const bool same_direction = vertices[at(TET_EDGES[k][0])] == m_adjacency.edges[at(edge)][0];
      crossings.ratio[k] = same_direction ? m_edge_ratio[at(edge)] : 1.0 - m_edge_ratio[at(edge)];
      crossings.upper_end[k] =
          static_cast<std::int8_t>(same_direction ? m_edge_upper_end[at(edge)] : -m_edge_upper_end[at(edge)]);
    }
    const std::array<Eigen::Vector3d, 4> rest = m_mesh.rest_corners(tet);
    auto cut = classify_tet_cut(rest, crossings, m_settings.vertex_snap_fraction, m_settings.min_volume_fraction);
    if (!cut) continue;
    if (m_tet_cut_count[at(tet)] >= MAX_PIECE_CUTS) {  // the pieces' capacity (convex_piece.hpp)
      if (m_tet_ignored_session[at(tet)] != m_cut_id) {
        m_tet_ignored_session[at(tet)] = m_cut_id;
        ++report.ignored_cuts;
      }
      continue;
    }
    cut->tet = tet;
    cut->cut_id = m_cut_id;
    cut->min_volume_fraction = m_settings.min_volume_fraction;
    m_tet_cut_session[at(tet)] = m_cut_id;
    ++m_tet_cut_count[at(tet)];
    m_new_cuts.push_back(*cut);
  }
}

}  // namespace tissue
