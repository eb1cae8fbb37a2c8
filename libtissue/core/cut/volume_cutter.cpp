// Volume collision detection for cutting (see volume_cutter.hpp; dissertation 4.3.2).
#include "core/cut/volume_cutter.hpp"

#include "core/collide/geometry.hpp"
#include "core/cut/cut_geometry.hpp"
#include "core/index_cast.hpp"
#include "core/material/material.hpp"
#include "core/wall_clock.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <sstream>
#include <string>

namespace tissue {
namespace {

/// The local vertices a cut puts above, as bits.
std::uint8_t above_mask(const TetCut& cut) {
  unsigned mask = 0u;
  for (unsigned v = 0; v < 4; ++v) {
    if (cut.side[v] > 0) mask |= 1u << v;
  }
  return static_cast<std::uint8_t>(mask);
}

bool is_finite(const Blade& blade) { return blade.tip_m.allFinite() && blade.handle_m.allFinite(); }

/// True when the closed segment a-b meets the tet x: an end inside, or a face crossed (algorithm 4's test).
bool segment_touches_tet(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const std::array<Eigen::Vector3d, 4>& x) {
  for (const Eigen::Vector3d* end : {&a, &b}) {
    const auto barycentric = tet_barycentric(*end, x[0], x[1], x[2], x[3]);
    if (barycentric && barycentric->minCoeff() >= 0.0) return true;
  }
  for (const auto& face : TET_FACES) {
    if (intersect_segment_triangle(a, b, x[to_size(face[0])], x[to_size(face[1])], x[to_size(face[2])])) return true;
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

  /// Where the edge a-b (lengthened by EDGE_ROUND_OFF_EXTENSION) crosses the sweep: the ratio along
  /// a -> b, in [0, 1]; the first triangle wins when it crosses both.
  [[nodiscard]] std::optional<double> cross_edge(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    const Eigen::Vector3d direction = b - a;
    const Eigen::Vector3d from = a - EDGE_ROUND_OFF_EXTENSION * direction;
    const Eigen::Vector3d to = b + EDGE_ROUND_OFF_EXTENSION * direction;
    for (std::size_t m = 0; m < 2; ++m) {
      const auto hit = intersect_segment_triangle(from, to, triangles[m][0], triangles[m][1], triangles[m][2]);
      if (!hit) continue;
      return std::clamp(hit->segment_parameter * (1.0 + 2.0 * EDGE_ROUND_OFF_EXTENSION) - EDGE_ROUND_OFF_EXTENSION,
                        0.0, 1.0);
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
  m_tet_cut_turn_rad.assign(tets, 0.0);
  m_tet_ignored_session.assign(tets, -1);
  m_tet_cut_count.assign(tets, 0);
  m_tet_cut_above.assign(tets, 0);
  m_edge_stamp.assign(edges, 0);
  m_edge_session.assign(edges, -1);
  m_edge_ratio.assign(edges, 0.0);
  m_edge_turn_rad.assign(edges, 0.0);
  const std::size_t vertices = static_cast<std::size_t>(mesh.vertex_count());
  m_vertex_session.assign(vertices, -1);
  m_vertex_side.assign(vertices, 0);
  m_vertex_distance_m.assign(vertices, 0.0);
  m_vertex_turn_rad.assign(vertices, 0.0);
  // Each vertex's snap distance from its shortest rest edge, its reach from its longest.
  m_vertex_snap_m.assign(vertices, std::numeric_limits<double>::infinity());
  m_vertex_reach_m.assign(vertices, 0.0);
  for (const auto& ends : adjacency.edges) {
    const double length_m = (mesh.rest_positions_m[to_size(ends[1])] - mesh.rest_positions_m[to_size(ends[0])]).norm();
    for (const int v : ends) {
      m_vertex_snap_m[to_size(v)] = std::min(m_vertex_snap_m[to_size(v)], settings.vertex_snap_fraction * length_m);
      m_vertex_reach_m[to_size(v)] = std::max(m_vertex_reach_m[to_size(v)], length_m);
    }
  }
  for (double& snap_m : m_vertex_snap_m) {
    if (!std::isfinite(snap_m)) snap_m = 0.0;  // a vertex on no edge
  }
  m_new_vertices.reserve(vertices);
  m_watched.reserve(vertices);
  m_watched_flag.assign(vertices, 0);
  m_fitted_close.assign(vertices, -1);
  m_on_blade.reserve(vertices);
  m_session_vertices.reserve(vertices);
  m_closing.reserve(4 * tets);
  // Each tet (edge) enters a list at most once per step: these capacities are never exceeded.
  m_active.reserve(tets);
  m_visited.reserve(tets);
  m_stack.reserve(tets);
  m_candidates.reserve(tets);
  m_new_cuts.reserve(tets);
  m_seeds.reserve(surface.triangles.size());
  // The BVH also holds the cut faces added later: room for as many again.
  m_hits.reserve(2 * surface.triangles.size());
  m_box_triangles.reserve(2 * surface.triangles.size());
}

std::optional<double> VolumeCutter::edge_crossing(int edge) const {
  if (m_cut_id < 0 || !crossed_now(edge)) return std::nullopt;
  return m_edge_ratio[to_size(edge)];
}

CutStepReport VolumeCutter::end_cut(const Eigen::VectorXd& positions_m) {
  if (m_cutting) validate_positions(positions_m, "VolumeCutter::end_cut");
  const auto start = std::chrono::steady_clock::now();
  m_new_cuts.clear();
  m_candidates.clear();
  m_new_vertices.clear();
  CutStepReport report;
  if (m_cutting) {
    report.cut_id = m_cut_id;
    close_session(report, positions_m);
  }
  m_cutting = false;
  m_active.clear();
  m_idle_steps = 2;  // ended on purpose: the next session is a new stroke
  report.newly_cut_tets = static_cast<int>(m_new_cuts.size());
  report.seconds = seconds_since(start);
  return report;
}

void VolumeCutter::save(SessionState& state) const {
  state.cutting = m_cutting;
  state.cut_id = m_cut_id;
  state.tet_cut_session = m_tet_cut_session;
  state.tet_cut_turn_rad = m_tet_cut_turn_rad;
  state.tet_ignored_session = m_tet_ignored_session;
  state.tet_cut_count = m_tet_cut_count;
  state.tet_cut_above = m_tet_cut_above;
  state.edge_session = m_edge_session;
  state.edge_ratio = m_edge_ratio;
  state.edge_turn_rad = m_edge_turn_rad;
  state.vertex_session = m_vertex_session;
  state.vertex_side = m_vertex_side;
  state.vertex_distance_m = m_vertex_distance_m;
  state.vertex_turn_rad = m_vertex_turn_rad;
  state.watched = m_watched;
  state.idle_steps = m_idle_steps;
  state.record_epoch = m_record_epoch;
  state.turn_rad = m_turn_rad;
  state.session_vertices = m_session_vertices;
  state.plane = {m_plane.tip_m, m_plane.blade_m, m_plane.normal, m_plane.ahead, m_plane.anchor_m, m_last_stroke_normal};
  state.plane_valid = m_plane.valid;
  state.active = m_active;
}

void VolumeCutter::restore(const SessionState& state) {
  const auto fail = [](const std::string& what) { throw std::invalid_argument("VolumeCutter::restore: " + what); };
  const size_t tets = m_tet_cut_session.size();
  const size_t edges = m_edge_session.size();
  const size_t vertices = m_vertex_session.size();
  if (state.vertex_session.size() != vertices || state.vertex_side.size() != vertices) {
    fail("the state's vertex sides are of another mesh (" + std::to_string(state.vertex_session.size()) +
         " vertices; this one has " + std::to_string(vertices) + ")");
  }
  if (!std::all_of(state.vertex_side.begin(), state.vertex_side.end(),
                   [](std::int8_t side) { return side >= -1 && side <= 1; })) {
    fail("a vertex's side is not -1, 0 or +1");
  }
  const auto all_finite = [](const std::vector<double>& values) {
    return std::all_of(values.begin(), values.end(), [](double a) { return std::isfinite(a); });
  };
  if (state.vertex_turn_rad.size() != vertices || state.tet_cut_turn_rad.size() != tets ||
      state.edge_turn_rad.size() != edges || !std::isfinite(state.turn_rad) || !all_finite(state.vertex_turn_rad) ||
      !all_finite(state.tet_cut_turn_rad) || !all_finite(state.edge_turn_rad)) {
    fail("the state's blade turning is of another mesh or not finite");
  }
  if (state.vertex_distance_m.size() != vertices ||
      !std::all_of(state.vertex_distance_m.begin(), state.vertex_distance_m.end(), [](double d) { return std::isfinite(d); })) {
    fail("the state's vertex distances are of another mesh or not finite");
  }
  if (state.watched.size() > vertices ||
      !std::all_of(state.watched.begin(), state.watched.end(),
                   [&](int v) { return v >= 0 && static_cast<size_t>(v) < vertices; })) {
    fail("a watched vertex is out of range");
  }
  if (state.session_vertices.size() > vertices ||
      !std::all_of(state.session_vertices.begin(), state.session_vertices.end(),
                   [&](int v) { return v >= 0 && static_cast<size_t>(v) < vertices; })) {
    fail("a session vertex is out of range");
  }
  if (!std::all_of(state.plane.begin(), state.plane.end(), [](const Eigen::Vector3d& p) { return p.allFinite(); })) {
    fail("the blade's plane is not finite");
  }
  if (state.tet_cut_session.size() != tets || state.tet_ignored_session.size() != tets ||
      state.tet_cut_count.size() != tets || state.tet_cut_above.size() != tets ||
      state.edge_session.size() != edges || state.edge_ratio.size() != edges) {
    fail("the state is of another mesh (" + std::to_string(state.tet_cut_session.size()) + " tets, " +
         std::to_string(state.edge_session.size()) + " edges; this one has " + std::to_string(tets) + " and " +
         std::to_string(edges) + ")");
  }
  if (state.cut_id < -1 || (state.cutting && state.cut_id < 0)) fail("bad session id " + std::to_string(state.cut_id));
  const auto session_ok = [&](int session) { return session >= -1 && session <= state.cut_id; };
  if (!std::all_of(state.tet_cut_session.begin(), state.tet_cut_session.end(), session_ok) ||
      !std::all_of(state.tet_ignored_session.begin(), state.tet_ignored_session.end(), session_ok) ||
      !std::all_of(state.edge_session.begin(), state.edge_session.end(),
                   [&](int epoch) { return epoch >= -1 && epoch <= state.record_epoch; }) ||
      !std::all_of(state.vertex_session.begin(), state.vertex_session.end(), session_ok)) {
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
  std::copy(state.tet_cut_turn_rad.begin(), state.tet_cut_turn_rad.end(), m_tet_cut_turn_rad.begin());
  std::copy(state.tet_ignored_session.begin(), state.tet_ignored_session.end(), m_tet_ignored_session.begin());
  std::copy(state.tet_cut_count.begin(), state.tet_cut_count.end(), m_tet_cut_count.begin());
  std::copy(state.tet_cut_above.begin(), state.tet_cut_above.end(), m_tet_cut_above.begin());
  std::copy(state.edge_session.begin(), state.edge_session.end(), m_edge_session.begin());
  std::copy(state.edge_ratio.begin(), state.edge_ratio.end(), m_edge_ratio.begin());
  std::copy(state.edge_turn_rad.begin(), state.edge_turn_rad.end(), m_edge_turn_rad.begin());
  std::copy(state.vertex_session.begin(), state.vertex_session.end(), m_vertex_session.begin());
  std::copy(state.vertex_side.begin(), state.vertex_side.end(), m_vertex_side.begin());
  std::copy(state.vertex_distance_m.begin(), state.vertex_distance_m.end(), m_vertex_distance_m.begin());
  std::copy(state.vertex_turn_rad.begin(), state.vertex_turn_rad.end(), m_vertex_turn_rad.begin());
  m_turn_rad = state.turn_rad;
  m_idle_steps = std::clamp(state.idle_steps, 0, 2);
  m_record_epoch = state.record_epoch;
  std::fill(m_watched_flag.begin(), m_watched_flag.end(), std::uint8_t{0});
  m_watched.assign(state.watched.begin(), state.watched.end());
  for (const int vertex : m_watched) m_watched_flag[to_size(vertex)] = 1;
  m_session_vertices.assign(state.session_vertices.begin(), state.session_vertices.end());
  m_plane = BladePlane{state.plane[0], state.plane[1], state.plane[2], state.plane[3], state.plane[4], state.plane_valid};
  m_last_stroke_normal = state.plane[5];
  m_active.assign(state.active.begin(), state.active.end());
}

void VolumeCutter::validate(const Blade& previous, const Blade& current, const Eigen::VectorXd& positions_m,
                            const SurfaceBvh& bvh) const {
  if (!is_finite(previous) || !is_finite(current)) {
    throw std::invalid_argument("VolumeCutter::step: blade position is not finite");
  }
  validate_positions(positions_m, "VolumeCutter::step");
  if (bvh.triangle_count() < static_cast<int>(m_surface.triangles.size())) {
    throw std::invalid_argument("VolumeCutter::step: the BVH has fewer triangles than the surface");
  }
}

void VolumeCutter::validate_positions(const Eigen::VectorXd& positions_m, const char* call) const {
  if (positions_m.size() < 3 * static_cast<Eigen::Index>(m_mesh.vertex_count())) {
    throw std::invalid_argument(std::string(call) + ": " + std::to_string(positions_m.size()) +
                                " position entries for " + std::to_string(m_mesh.vertex_count()) + " vertices");
  }
  if (!positions_m.allFinite()) throw std::invalid_argument(std::string(call) + ": a vertex position is not finite");
}

CutStepReport VolumeCutter::step(const Blade& previous, const Blade& current, const Eigen::VectorXd& positions_m,
                                 const SurfaceBvh& bvh) {
  validate(previous, current, positions_m, bvh);
  const auto start = std::chrono::steady_clock::now();
  m_new_cuts.clear();
  m_visited.clear();
  m_new_vertices.clear();
  m_on_blade.clear();
  m_new_crossings = 0;
  m_candidates.clear();
  m_seeds.clear();
  CutStepReport report;
  const Blade sweep_start = swept_from(previous, current);
  const Sweep sweep(sweep_start, current);
  const bool was_cutting = m_cutting;
  if (!was_cutting) {
    // Algorithm 5, first part: the blade (or, added, its sweep) meets the surface.
    ++m_stamp;
    find_initial_tets(current, positions_m, bvh);
    ++m_stamp;
    // From the previous blade itself: the sweep's overlap behind it would start a session again
    // just after one ended, where the blade left the body, and cut the tets there twice.
    collect_surface_seeds(Sweep(previous, current), positions_m, bvh);
    if (m_active.empty() && m_seeds.empty()) {
      m_idle_steps = std::min(m_idle_steps + 1, 2);
      report.seconds = seconds_since(start);
      return report;
    }
    m_seeds.clear();
    collect_surface_seeds(sweep, positions_m, bvh);
    m_cutting = true;
  }
  // A session that ended in the last step (a blade through a vertex or along an edge exactly may
  // touch no tet for a step) goes on when the blade moves on in its plane: one stroke, one session.
  const bool new_session = !was_cutting && !(m_idle_steps == 0 && continues_plane(previous, current));
  if (!was_cutting) ++m_record_epoch;  // edge crossings are recorded afresh (algorithm 3) at every start
  if (new_session) {
    ++m_cut_id;
    m_session_vertices.clear();
    for (const int vertex : m_watched) m_watched_flag[to_size(vertex)] = 0;
    m_watched.clear();
  }
  if (was_cutting) ++m_stamp;
  if (!was_cutting && !new_session) m_plane.anchor_m = 0.5 * (previous.tip_m + previous.handle_m);  // going on
  update_plane(previous, current, new_session);
  // How far behind the blade the sweep starts, in the plane's direction of motion (<= 0).
  m_strip_back_m = std::min({0.0, (sweep_start.tip_m - current.tip_m).dot(m_plane.ahead),
                             (sweep_start.handle_m - current.tip_m).dot(m_plane.ahead)});
  // Algorithm 2 from every active tet, then from where the sweep crosses the surface elsewhere.
  for (const int tet : m_active) search_from(tet, sweep, positions_m);
  if (was_cutting) collect_surface_seeds(sweep, positions_m, bvh);
  for (const int tet : m_seeds) search_from(tet, sweep, positions_m);

  find_next_active(current, positions_m);
  if (m_active.empty()) {
    // A blade through a vertex or along an edge exactly may touch none of the tets the sweep
    // reached while it is still in the body: the session goes on from where it enters the surface.
    ++m_stamp;
    find_initial_tets(current, positions_m, bvh);
  }
  complete_touched_tets(report, positions_m);
  if (m_active.empty()) {
    close_session(report, positions_m);
    m_cutting = false;
    m_idle_steps = 0;
  }

  report.cutting = m_cutting;
  report.cut_id = m_cut_id;
  report.intersected_tets = static_cast<int>(m_visited.size());
  report.active_tets = static_cast<int>(m_active.size());
  report.new_edge_crossings = m_new_crossings;
  report.newly_cut_tets = static_cast<int>(m_new_cuts.size());
  report.seconds = seconds_since(start);
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
    const int entry = m_surface.triangle_tet[to_size(hit.triangle)];
    if (m_tet_stamp[to_size(entry)] == m_stamp) continue;
    m_tet_stamp[to_size(entry)] = m_stamp;
    m_stack.push_back(entry);
    while (!m_stack.empty()) {
      const int tet = m_stack.back();
      m_stack.pop_back();
      m_active.push_back(tet);
      const Tet& vertices = m_mesh.tets[to_size(tet)];
      for (std::size_t k = 0; k < 4; ++k) {
        const int next = m_adjacency.face_neighbor[to_size(tet)][k];
        if (next < 0 || m_tet_stamp[to_size(next)] == m_stamp) continue;
        const auto& face = TET_FACES[k];
        if (intersect_segment_triangle(blade.tip_m, blade.handle_m,
                                       vertex_position(positions_m, vertices[to_size(face[0])]),
                                       vertex_position(positions_m, vertices[to_size(face[1])]),
                                       vertex_position(positions_m, vertices[to_size(face[2])]))) {
          m_tet_stamp[to_size(next)] = m_stamp;
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
    const int tet = m_surface.triangle_tet[to_size(triangle)];
    if (m_tet_stamp[to_size(tet)] == m_stamp) continue;
    const auto& vertices = m_surface.triangles[to_size(triangle)];
    if (sweep.crosses_triangle(vertex_position(positions_m, vertices[0]), vertex_position(positions_m, vertices[1]),
                               vertex_position(positions_m, vertices[2]))) {
      m_seeds.push_back(tet);
    }
  }
}

void VolumeCutter::push_unvisited(int tet) {
  if (m_tet_stamp[to_size(tet)] == m_stamp) return;
  m_tet_stamp[to_size(tet)] = m_stamp;  // algorithm 2's isVisited
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
  for (const int edge : m_adjacency.tet_edges[to_size(tet)]) process_edge(edge, sweep, positions_m);
  const Tet& vertices = m_mesh.tets[to_size(tet)];
  // A vertex of a tet the sweep touches that the blade passed in this step (behind the blade, not
  // behind the sweep's start) gets its side now, for the session and every tet around it; one still
  // ahead of the blade is watched until it is passed (pass_watched).
  for (const int vertex : vertices) {
    decide_if_passed(vertex, positions_m);
  }
  // Added: step across faces the sweep's boundary crosses (no edge need be crossed there).
  for (std::size_t k = 0; k < 4; ++k) {
    const int next = m_adjacency.face_neighbor[to_size(tet)][k];
    if (next < 0 || m_tet_stamp[to_size(next)] == m_stamp) continue;
    const auto& face = TET_FACES[k];
    if (sweep.boundary_crosses(vertex_position(positions_m, vertices[to_size(face[0])]),
                               vertex_position(positions_m, vertices[to_size(face[1])]),
                               vertex_position(positions_m, vertices[to_size(face[2])]))) {
      push_unvisited(next);
    }
  }
}

// Each edge is tested once per step; the first crossing in a session is recorded (algorithm 3) and
// the tets around it are searched next.
void VolumeCutter::process_edge(int edge, const Sweep& sweep, const Eigen::VectorXd& positions_m) {
  if (m_edge_stamp[to_size(edge)] == m_stamp) return;
  m_edge_stamp[to_size(edge)] = m_stamp;
  const auto& ends = m_adjacency.edges[to_size(edge)];
  const auto crossing = sweep.cross_edge(vertex_position(positions_m, ends[0]), vertex_position(positions_m, ends[1]));
  if (!crossing) return;
  if (!crossed_now(edge)) {
    m_edge_session[to_size(edge)] = m_record_epoch;
    m_edge_turn_rad[to_size(edge)] = m_turn_rad;
    m_edge_ratio[to_size(edge)] = *crossing;
    ++m_new_crossings;
  }
  const int end = m_adjacency.edge_tets_begin[to_size(edge) + 1];
  for (int k = m_adjacency.edge_tets_begin[to_size(edge)]; k < end; ++k)
    push_unvisited(m_adjacency.edge_tets[to_size(k)]);
}

// Algorithm 4: the searched tets that the blade still touches (an end inside counts, so the
// handle may be inside the body).
void VolumeCutter::find_next_active(const Blade& blade, const Eigen::VectorXd& positions_m) {
  m_active.clear();
  for (const int tet : m_visited) {
    const Tet& vertices = m_mesh.tets[to_size(tet)];
    const std::array<Eigen::Vector3d, 4> x = {
        vertex_position(positions_m, vertices[0]), vertex_position(positions_m, vertices[1]),
        vertex_position(positions_m, vertices[2]), vertex_position(positions_m, vertices[3])};
    if (segment_touches_tet(blade.tip_m, blade.handle_m, x)) m_active.push_back(tet);
  }
}

// A tet is cut when the sides of all its vertices are decided in this session and differ. Decisions
// are made only here and in visit: the candidates are the tets around this step's decisions.
void VolumeCutter::complete_touched_tets(CutStepReport& report, const Eigen::VectorXd& positions_m) {
  // The vertices seen ahead of the blade that it has passed since, whether or not a tet of theirs
  // is touched now (off the blade's plane, beyond the part of a tet it crossed; or carried past a
  // step's sweep by the body).
  pass_watched(positions_m);
  decide_around_vertices_on_blade(positions_m);
  cut_around_new_vertices(report);
}

void VolumeCutter::cut_around_new_vertices(CutStepReport& report) {
  for (const int vertex : m_new_vertices) {
    const int end = m_adjacency.vertex_tets_begin[to_size(vertex) + 1];
    for (int k = m_adjacency.vertex_tets_begin[to_size(vertex)]; k < end; ++k) {
      const int tet = m_adjacency.vertex_tets[to_size(k)];
      if (m_candidate_stamp[to_size(tet)] == m_stamp) continue;
      m_candidate_stamp[to_size(tet)] = m_stamp;
      m_candidates.push_back(tet);
    }
  }
  m_new_vertices.clear();
  const double end_margin = MIN_CUT_POINT_MARGIN;  // the classification is snapped, never the geometry
  for (const int tet : m_candidates) {
    if (cut_now(tet)) continue;
    const auto cut = cut_of(tet, end_margin);
    if (!cut) continue;
    if (m_tet_cut_count[to_size(tet)] >= MAX_PIECE_CUTS) {  // the pieces' capacity (convex_piece.hpp)
      if (m_tet_ignored_session[to_size(tet)] != m_cut_id) {
        m_tet_ignored_session[to_size(tet)] = m_cut_id;
        ++report.ignored_cuts;
      }
      continue;
    }
    // A session that continues the last one's stroke (a session started again where a blade moving
    // through a vertex or an edge touched no tet for a step: the same plane) and gives the tet's
    // vertices the sides the last one gave them makes no new cut: the pieces are those it has.
    const std::uint8_t above = above_mask(*cut);
    const std::uint8_t last = m_tet_cut_above[to_size(tet)];
    if (m_tet_cut_count[to_size(tet)] > 0 && m_tet_cut_session[to_size(tet)] == m_cut_id - 1 &&
        continues_last_stroke() && (last == above || last == (~above & 0xFu))) {
      continue;
    }
    m_tet_cut_session[to_size(tet)] = m_cut_id;
    m_tet_cut_turn_rad[to_size(tet)] = m_turn_rad;
    m_tet_cut_above[to_size(tet)] = above;
    ++m_tet_cut_count[to_size(tet)];
    m_new_cuts.push_back(*cut);
  }
  m_candidates.clear();
}

}  // namespace tissue
