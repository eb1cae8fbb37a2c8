// VolumeCutter: semi-progressive cutting by volume collision detection (dissertation 4.3.2,
// algorithms 1-5). The blade is the segment tip-handle; between two steps it sweeps two
// triangles. A local neighbour search from the tets the blade touches finds the tets the sweep
// touches and records where it crosses mesh edges (once per cutting session).
//
// Which tets are cut is decided by their vertices (issue 41, vertex_sides.cpp): each vertex gets one
// side of the blade's plane per session (per passage of a spiral), when the blade passes it, shared
// by every tet around it; a tet is cut as soon as the blade has passed all its vertices and they lie
// on both sides (a vertex within its snap distance of the blade counts above, in every tet). So
// the cut tets always separate the decided vertices: no tet holds the two sides together, however
// the body moves while the blade passes. Each cut goes to the XFEM as a TetCut; a tet may be cut by
// up to MAX_PIECE_CUTS sessions (issue 21).
//
// Additions to the dissertation's algorithms, for robustness:
//  * A session also starts when the sweep (not only the current blade) crosses the surface, so a
//    blade that passes through a thin part between two steps still cuts.
//  * Every step also seeds the search from surface triangles the sweep crosses, so a fast sweep
//    that leaves and re-enters the body within one step misses nothing.
//  * Besides crossed edges (algorithm 2) the search also steps across tet faces that the sweep's
//    boundary (the two blade positions and the paths of tip and handle) crosses. Then it reaches
//    every tet the sweep touches, and the next active list (algorithm 4) is complete even where
//    the sweep crosses a tet without crossing any of its edges (near the tip, or a handle inside).
//  * Each edge test is guarded against round-off at the edge's ends (EDGE_ROUND_OFF_EXTENSION).
//
// A session (one cut_id) runs from the step in which the blade or its sweep meets the surface to
// the step after which the blade touches no tet (then close_session), or to end_cut(); one that
// ended in the last step goes on if the blade moves on in its plane. A later session that passes a
// cut tet cuts it again (the XFEM splits the pieces it passes through, split_pieces). A tet that
// carries MAX_PIECE_CUTS cuts already is not cut again: counted once per session in
// CutStepReport::ignored_cuts. The search starts from the previous step's active tets: if the
// body moves so far in one step that the blade has left all of them, only the parts of the sweep
// that reach the surface are found.
#pragma once

#include "core/collide/surface_bvh.hpp"
#include "core/fem/convex_piece.hpp"
#include "core/fem/tet_cut.hpp"
#include "core/mesh/tet_mesh.hpp"
#include "core/mesh/topology.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace tissue {

/// Before an edge is tested against the sweep it is lengthened by this fraction of its length at
/// both ends, and the crossing is clamped to the edge: a sweep exactly through a vertex is then
/// seen, at that vertex, from every edge there, whatever the round-off.
inline constexpr double EDGE_ROUND_OFF_EXTENSION = 1e-9;

/// The blade's plane, in which a vertex's side is decided, turns with the blade's direction of
/// motion measured over at least this distance of the blade's middle (and over the first step of a
/// session): a hand's tremor over a fraction of a millimetre does not tilt it.
inline constexpr double BLADE_PLANE_BASELINE_M = 1e-3;
/// A blade moving within this sine of its own direction (a plunge) keeps the plane it had.
inline constexpr double BLADE_PLANE_SINE_FLOOR = 1e-6;

/// A vertex is passed again, and decided again, when the blade comes back to it after its plane
/// turned through more than this (the next turn of a spiral); a tet is cut from decisions made
/// within half of it.
inline constexpr double PASSAGE_TURN_RAD = 3.14159265358979323846;

/// Two sessions whose blade planes agree to this cosine (5 degrees), the second's blade within
/// SAME_STROKE_OFFSET_M of the first's plane, are one stroke continued.
inline constexpr double SAME_STROKE_COSINE = 0.996;
inline constexpr double SAME_STROKE_OFFSET_M = 1e-4;

/// close_session decides vertices in at most this many rounds (each round around the last).
inline constexpr int MAX_CLOSING_ROUNDS = 8;

/// The fit of close_session over a vertex's decided neighbours (rest positions scaled to the star's
/// size) counts only pivots above this fraction of the largest: neighbours near one plane through
/// the vertex do not determine its distance.
inline constexpr double FIT_PIVOT_FLOOR = 1e-3;

/// A cut point stays at least this fraction of its edge from either end (with vertex_snap_fraction
/// 0 too), so that a tet's cut points are distinct and its cut plane defined.
inline constexpr double MIN_CUT_POINT_MARGIN = 1e-6;

/// Each step's sweep starts this fraction of the tip's and of the handle's travel behind the
/// previous blade. Blade and body both move between two steps, and an edge is tested at its
/// current position only: an edge lying on the previous blade's line (a step that ended exactly on
/// it) that the body then moves back by a hair would be missed by both sweeps. The overlap sees it;
/// an edge crossed already keeps its first crossing.
inline constexpr double SWEEP_BACK_OVERLAP = 0.1;

/// The cutting edge: the segment from the tip to the handle [m].
struct Blade {
  Eigen::Vector3d tip_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d handle_m = Eigen::Vector3d::Zero();
};

/// Where a step's sweep starts: the previous blade moved back along each end's path by
/// SWEEP_BACK_OVERLAP of its travel (the sweep ends at the current blade).
Blade swept_from(const Blade& previous, const Blade& current);

struct CutterSettings {
  /// An edge crossing within this fraction of the edge length from an end passes through that
  /// vertex (docs/DESIGN.md, "Cutting": a cut that passes within eps of a vertex is treated as
  /// passing through it). In [0, 0.5); 0 takes crossings as computed.
  double vertex_snap_fraction = 1e-3;
  /// V_a/V is clamped to [this, 1 - this], so that neither part of a cut tet has (almost) no
  /// stiffness and mass (eq. 3.21-3.23, 4.16). In [SMALLEST_MIN_VOLUME_FRACTION, 0.5).
  double min_volume_fraction = DEFAULT_MIN_VOLUME_FRACTION;
};

/// Throws ParameterError unless both fractions are in their ranges (the one place they are checked).
void validate(const CutterSettings& settings);

/// What one step did (dissertation table 6.4 reports `seconds` and `newly_cut_tets`).
struct CutStepReport {
  bool cutting = false;         ///< a session is open after the step
  int cut_id = -1;              ///< the session this step belonged to; -1 when there was none
  int intersected_tets = 0;     ///< tets visited by the neighbour search (algorithm 2's list)
  int active_tets = 0;          ///< tets the blade touches after the step (algorithm 4)
  int new_edge_crossings = 0;   ///< edges crossed for the first time in this session
  int newly_cut_tets = 0;       ///< tets completed by this step (= new_cuts().size())
  int ignored_cuts = 0;         ///< tets this session cut that carry MAX_PIECE_CUTS cuts already (not cut again)
  double seconds = 0.0;         ///< wall time of the step
};

class VolumeCutter {
 public:
  /// `mesh`, `adjacency` and `surface` (extract_surface, build_adjacency of `mesh`) must outlive the
  /// cutter. Work arrays are sized here, so that a step does not allocate. Throws
  /// std::invalid_argument for settings out of range or inconsistent mesh data.
  VolumeCutter(const TetMesh& mesh, const TetAdjacency& adjacency, const SurfaceMesh& surface,
               CutterSettings settings = {});

  /// Algorithm 5 for the blade's move from `previous` to `current`. `positions_m`: current
  /// (deformed) positions, 3 per vertex, first the mesh vertices, then any further vertices the
  /// BVH's cut faces use (passed on to the BVH only); crossings are found in this configuration,
  /// volume fractions in the rest configuration. `bvh`: over the current surface
  /// (refitted); its triangle ids below surface.triangles.size() are the SurfaceMesh triangles,
  /// ids beyond (cut faces) are ignored. Throws std::invalid_argument, before changing any state,
  /// for a non-finite blade or position or for sizes that do not match the mesh.
  CutStepReport step(const Blade& previous, const Blade& current, const Eigen::VectorXd& positions_m,
                     const SurfaceBvh& bvh);

  /// The tets the last step completed, to be enriched by the XFEM (cleared by each step).
  [[nodiscard]] const std::vector<TetCut>& new_cuts() const { return m_new_cuts; }
  [[nodiscard]] bool cutting() const { return m_cutting; }
  /// The open session, or the last one; -1 before the first. Sessions count 0, 1, 2, ...
  [[nodiscard]] int cut_id() const { return m_cut_id; }
  /// The tets the blade touches after the last step (the seeds of the next search).
  [[nodiscard]] const std::vector<int>& active_tets() const { return m_active; }
  [[nodiscard]] bool is_cut(int tet) const { return m_tet_cut_session[static_cast<std::size_t>(tet)] >= 0; }
  /// The last session that cut `tet`, -1 if none did.
  [[nodiscard]] int cut_session(int tet) const { return m_tet_cut_session[static_cast<std::size_t>(tet)]; }
  /// How many sessions cut `tet`.
  [[nodiscard]] int cut_count(int tet) const { return m_tet_cut_count[static_cast<std::size_t>(tet)]; }
  /// Where the current (or last) session crossed `edge` (an id of TetAdjacency::edges {v0, v1}):
  /// the ratio r of the point (1 - r) x_v0 + r x_v1, or nothing if it did not cross it.
  [[nodiscard]] std::optional<double> edge_crossing(int edge) const;

  /// The side of the blade the current (or last) session gave `vertex`: +1 above, -1 below, 0 on
  /// the blade (within its snap distance); nothing if the blade has not passed it.
  /// True when the blade's plane turned through at most half PASSAGE_TURN_RAD between the decisions
  /// of the tet's vertices' sides: a tet is cut only from such decisions.
  [[nodiscard]] bool decided_in_one_passage(int tet) const { return one_passage(tet); }
  [[nodiscard]] std::optional<int> vertex_side(int vertex) const {
    if (m_cut_id < 0 || !side_decided(vertex)) return std::nullopt;
    return m_vertex_side[static_cast<std::size_t>(vertex)];
  }

  /// Ends the session where the blade is (the scalpel was taken away inside the body, or its mode
  /// changed): as when the blade leaves the body, the tets it went into are cut up to their far
  /// faces (close_session); those cuts are in new_cuts() (cleared by the next step or end_cut).
  /// `positions_m` as for step() (read only when a session is open). Throws std::invalid_argument,
  /// before changing any state, for positions that are not finite or do not match the mesh.
  CutStepReport end_cut(const Eigen::VectorXd& positions_m);

  /// What the cutter carries from step to step: the open session and every session's record of the
  /// tets and edges it cut. (The search stamps are per step and not part of it.)
  struct SessionState {
    bool cutting = false;
    int cut_id = -1;
    std::vector<int> tet_cut_session;
    std::vector<double> tet_cut_turn_rad;
    std::vector<int> tet_ignored_session;
    std::vector<std::int8_t> tet_cut_count;
    std::vector<std::uint8_t> tet_cut_above;
    std::vector<int> edge_session;
    std::vector<double> edge_ratio;
    std::vector<double> edge_turn_rad;
    std::vector<int> vertex_session;
    std::vector<std::int8_t> vertex_side;
    std::vector<double> vertex_distance_m;
    std::vector<double> vertex_turn_rad;
    std::vector<int> watched;
    int idle_steps = 2;
    int record_epoch = -1;
    double turn_rad = 0.0;
    std::vector<int> session_vertices;
    /// The blade's plane: tip, blade, normal, ahead, anchor (VolumeCutter::BladePlane); the last
    /// session's normal.
    std::array<Eigen::Vector3d, 6> plane{};
    bool plane_valid = false;
    std::vector<int> active;
  };
  void save(SessionState& state) const;
  /// Throws std::invalid_argument (nothing changed) when the sizes do not match the mesh or an id
  /// is out of range.
  void restore(const SessionState& state);

 private:
  struct Sweep;  // the two sweep triangles and their boundary, for one step

  void validate(const Blade& previous, const Blade& current, const Eigen::VectorXd& positions_m,
                const SurfaceBvh& bvh) const;
  void validate_positions(const Eigen::VectorXd& positions_m, const char* call) const;
  void find_initial_tets(const Blade& blade, const Eigen::VectorXd& positions_m, const SurfaceBvh& bvh);
  void collect_surface_seeds(const Sweep& sweep, const Eigen::VectorXd& positions_m, const SurfaceBvh& bvh);
  void search_from(int seed, const Sweep& sweep, const Eigen::VectorXd& positions_m);
  void visit(int tet, const Sweep& sweep, const Eigen::VectorXd& positions_m);
  void process_edge(int edge, const Sweep& sweep, const Eigen::VectorXd& positions_m);
  /// True when the blade moving from `previous` to `current` moves in the last session's plane.
  [[nodiscard]] bool continues_plane(const Blade& previous, const Blade& current) const;
  /// The blade's plane for this step (BladePlane), from the blade's motion since its anchor.
  void update_plane(const Blade& previous, const Blade& current, bool new_session);
  /// A vertex's place relative to the blade's plane now: along the blade (0 at the tip, 1 at the
  /// handle), ahead of it in its direction of motion [m], and above it [m].
  struct PlaneOffset {
    double along_blade = 0.0;
    double ahead_m = 0.0;
    double distance_m = 0.0;
    [[nodiscard]] bool within_span() const { return along_blade >= 0.0 && along_blade <= 1.0; }
  };
  [[nodiscard]] PlaneOffset plane_offset(int vertex, const Eigen::VectorXd& positions_m) const;
  /// Decides the vertex's side by its distance from the plane if the blade passed it in this step:
  /// within the blade's span, behind it and not behind the sweep's start; watches it while ahead.
  void decide_if_passed(int vertex, const Eigen::VectorXd& positions_m);
  /// Decides (or watches) the vertices of the tets around the vertices decided on the blade.
  void decide_around_vertices_on_blade(const Eigen::VectorXd& positions_m);
  /// Decides the watched vertices the blade has passed since they were seen ahead of it.
  void pass_watched(const Eigen::VectorXd& positions_m);
  /// Decides the vertex's side by the cut around it: the linear fit, over the rest positions of the
  /// decided vertices of its tets, of their distances from the blade, taken at its rest position.
  void decide_from_neighbours(int vertex, const Eigen::VectorXd& positions_m);
  void record_side(int vertex, double distance_m);
  /// True when the tet's vertices decided by the blade's passage (not by this closing's fit) lie on
  /// both sides (on the blade counts above), decided in one passage.
  [[nodiscard]] bool has_both_sides_passed(int tet) const;
  /// True when the blade turned through at most half PASSAGE_TURN_RAD between the decisions of the
  /// tet's vertices.
  [[nodiscard]] bool one_passage(int tet) const;
  /// True when the blade stopped in the tet: it passed some of its vertices (not decided by this
  /// closing's fit) and saw the others ahead of it (watched).
  [[nodiscard]] bool stopped_in(int tet) const;
  /// Cuts the tets around this step's decisions that are complete (cut_of).
  void cut_around_new_vertices(CutStepReport& report);
  /// At a session's end: decides, by the cut around them, the vertices the blade did not pass of the
  /// tets it went into (those seen ahead of it within its span) and of tets with vertices on both
  /// sides (within its span, not more than an edge ahead of it).
  void close_session(CutStepReport& report, const Eigen::VectorXd& positions_m);
  /// The tet's cut from its vertices' sides, if all are decided in this session and they differ.
  [[nodiscard]] std::optional<TetCut> cut_of(int tet, double end_margin) const;
  [[nodiscard]] bool side_decided(int vertex) const { return m_vertex_session[static_cast<std::size_t>(vertex)] == m_cut_id; }
  /// Decided in this session and in this passage: the blade's plane has not turned through
  /// PASSAGE_TURN_RAD since (a spiral's earlier turn decided it for the tets there, not for these).
  [[nodiscard]] bool decided_now(int vertex) const {
    return side_decided(vertex) && in_this_passage(m_vertex_turn_rad[static_cast<std::size_t>(vertex)]);
  }
  /// Cut in this session and in this passage (the next turn of a spiral tighter than the tet cuts it
  /// again).
  [[nodiscard]] bool cut_now(int tet) const {
    const auto t = static_cast<std::size_t>(tet);
    return m_tet_cut_session[t] == m_cut_id && in_this_passage(m_tet_cut_turn_rad[t]);
  }
  /// The edge's crossing recorded since the session (re)started, in this passage.
  [[nodiscard]] bool crossed_now(int edge) const {
    const auto e = static_cast<std::size_t>(edge);
    return m_edge_session[e] == m_record_epoch && in_this_passage(m_edge_turn_rad[e]);
  }
  /// Whether something the session did when its plane had turned through `turn_rad` belongs to this
  /// passage of the blade: the plane has not turned through PASSAGE_TURN_RAD since.
  [[nodiscard]] bool in_this_passage(double turn_rad) const { return m_turn_rad - turn_rad <= PASSAGE_TURN_RAD; }
  void push_unvisited(int tet);
  void find_next_active(const Blade& blade, const Eigen::VectorXd& positions_m);
  void complete_touched_tets(CutStepReport& report, const Eigen::VectorXd& positions_m);

  const TetMesh& m_mesh;
  const TetAdjacency& m_adjacency;
  const SurfaceMesh& m_surface;
  CutterSettings m_settings;

  bool m_cutting = false;
  int m_cut_id = -1;
  /// Each search gets a new stamp; a tet or edge carrying the current stamp was handled already,
  /// so a step never clears per-mesh arrays (its cost stays local).
  std::int64_t m_stamp = 0;

  std::vector<std::int64_t> m_tet_stamp;        ///< visited (algorithms 1, 2)
  std::vector<std::int64_t> m_candidate_stamp;  ///< already queued for the completion test
  std::vector<int> m_tet_cut_session;           ///< last session that cut the tet, -1 if uncut
  std::vector<double> m_tet_cut_turn_rad;       ///< how far that session's plane had turned then
  std::vector<std::int8_t> m_tet_cut_count;     ///< sessions that cut the tet
  std::vector<std::uint8_t> m_tet_cut_above;    ///< the local vertices the last cut put above (bits)
  std::vector<int> m_tet_ignored_session;       ///< last session that reported an ignored cut
  std::vector<std::int64_t> m_edge_stamp;       ///< tested against the current sweep
  std::vector<int> m_edge_session;              ///< record epoch whose crossing is recorded, -1 if none
  std::vector<double> m_edge_ratio;             ///< along {v0, v1}
  std::vector<double> m_edge_turn_rad;          ///< how far the plane had turned when it was recorded
  int m_new_crossings = 0;
  /// Each vertex's side of the blade's plane (+1 above, -1 below, 0 on it: within its snap distance,
  /// vertex_snap_fraction of its shortest edge), decided once per session when the blade has passed
  /// it and shared by every tet around it; the session that decided it (-1: none), and its signed
  /// distance from the plane then.
  std::vector<int> m_vertex_session;
  std::vector<std::int8_t> m_vertex_side;
  std::vector<double> m_vertex_distance_m;
  std::vector<double> m_vertex_reach_m;  ///< the longest rest edge at each vertex
  std::vector<double> m_vertex_turn_rad;  ///< how far the blade's plane had turned when it was decided
  double m_turn_rad = 0.0;                ///< how far the blade's plane turned in this session
  std::vector<double> m_vertex_snap_m;  ///< vertex_snap_fraction of its shortest rest edge
  std::vector<int> m_new_vertices;      ///< decided this step
  std::vector<int> m_session_vertices;  ///< decided in this session
  std::vector<int> m_closing;           ///< close_session's vertices to decide
  std::vector<int> m_on_blade;          ///< decided on the blade, their stars not yet decided
  std::int64_t m_close_count = 0;       ///< counts close_session calls
  std::vector<std::int64_t> m_fitted_close;  ///< the close_session call that decided the vertex by the fit
  std::vector<int> m_watched;           ///< seen ahead of the blade in a tet it touched, not yet passed
  std::vector<std::uint8_t> m_watched_flag;
  /// The plane of the blade's motion: through the current blade, its normal `normal` ("above"), and
  /// `ahead` the direction in which the blade moves within it; measured from `anchor_m`, where the
  /// blade's middle was when it was last turned. Not valid until the blade has moved in a session.
  struct BladePlane {
    Eigen::Vector3d tip_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d blade_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    Eigen::Vector3d ahead = Eigen::Vector3d::Zero();
    Eigen::Vector3d anchor_m = Eigen::Vector3d::Zero();
    bool valid = false;
  };
  BladePlane m_plane;
  Eigen::Vector3d m_last_stroke_normal = Eigen::Vector3d::Zero();  ///< the last session's plane (zero: none)
  /// True when this session's plane is the last session's (within SAME_STROKE_COSINE).
  [[nodiscard]] bool continues_last_stroke() const {
    return m_plane.valid && std::abs(m_plane.normal.dot(m_last_stroke_normal)) >= SAME_STROKE_COSINE;
  }
  double m_strip_back_m = 0.0;  ///< where this step's sweep starts, behind the blade (<= 0)
  int m_idle_steps = 2;         ///< steps without a session since the last ended (at most 2)
  int m_record_epoch = -1;      ///< counts session starts, reopened ones too: the edge records' key

  std::vector<int> m_active;
  std::vector<int> m_visited;     ///< algorithm 2's intersected list of this step
  std::vector<int> m_stack;       ///< explicit stack of the searches (no recursion)
  std::vector<int> m_seeds;       ///< tets of surface triangles the sweep crosses
  std::vector<int> m_candidates;  ///< tets around them
  std::vector<TetCut> m_new_cuts;
  std::vector<SurfaceBvh::SegmentHit> m_hits;
  std::vector<int> m_box_triangles;
};

}  // namespace tissue
