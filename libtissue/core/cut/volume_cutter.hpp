// VolumeCutter: semi-progressive cutting by volume collision detection (dissertation 4.3.2,
// algorithms 1-5). The blade is the segment tip-handle; between two steps it sweeps two
// triangles. A local neighbour search from the tets the blade touches records where the sweep
// crosses mesh edges (once per cutting session), and every tet whose recorded crossings separate
// its vertices is handed to the XFEM as a TetCut as soon as it is cut completely (once per session;
// a tet may be cut by up to MAX_PIECE_CUTS sessions, issue 21).
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
// the step after which the blade touches no tet, or to end_cut(). When a tet is complete, and how
// its TetCut is computed, is decided by classify_tet_cut (cut_geometry.hpp) on this session's
// crossings of the tet's edges: a later session that crosses a cut tet completely cuts it again (the
// XFEM splits the pieces it passes through, split_pieces). A tet that carries MAX_PIECE_CUTS cuts
// already is not cut again: counted once per session in CutStepReport::ignored_cuts. The search
// starts from the previous step's active tets: if the
// body moves so far in one step that the blade has left all of them, only the parts of the sweep
// that reach the surface are found.
#pragma once

#include "core/collide/surface_bvh.hpp"
#include "core/fem/convex_piece.hpp"
#include "core/fem/tet_cut.hpp"
#include "core/mesh/tet_mesh.hpp"
#include "core/mesh/topology.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <vector>

namespace tissue {

/// Before an edge is tested against the sweep it is lengthened by this fraction of its length at
/// both ends, and the crossing is clamped to the edge: a sweep exactly through a vertex is then
/// seen, at that vertex, from every edge there, whatever the round-off.
inline constexpr double EDGE_ROUND_OFF_EXTENSION = 1e-9;

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

/// The floor of CutterSettings::min_volume_fraction. Below it a part's ghost unknowns weigh ~1e-16
/// of their tet: a capped PCG solve moves them freely and the next enrichment gives them mass, so
/// the energy jumps (tests/extremes: 5.7 times the work put in at 1e-300; bounded at 1e-12).
inline constexpr double SMALLEST_MIN_VOLUME_FRACTION = 1e-12;

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
  /// How many sessions cut `tet`.
  [[nodiscard]] int cut_count(int tet) const { return m_tet_cut_count[static_cast<std::size_t>(tet)]; }
  /// Where the current (or last) session crossed `edge` (an id of TetAdjacency::edges {v0, v1}):
  /// the ratio r of the point (1 - r) x_v0 + r x_v1, or nothing if it did not cross it.
  [[nodiscard]] std::optional<double> edge_crossing(int edge) const;

  /// Ends the session (the tool changed mode): tets cut partially stay uncut.
  void end_cut();

  /// What the cutter carries from step to step: the open session and every session's record of the
  /// tets and edges it cut. (The search stamps are per step and not part of it.)
  struct SessionState {
    bool cutting = false;
    int cut_id = -1;
    std::vector<int> tet_cut_session;
    std::vector<int> tet_ignored_session;
    std::vector<std::int8_t> tet_cut_count;
    std::vector<int> edge_session;
    std::vector<double> edge_ratio;
    std::vector<std::int8_t> edge_upper_end;
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
  void find_initial_tets(const Blade& blade, const Eigen::VectorXd& positions_m, const SurfaceBvh& bvh);
  void collect_surface_seeds(const Sweep& sweep, const Eigen::VectorXd& positions_m, const SurfaceBvh& bvh);
  void search_from(int seed, const Sweep& sweep, const Eigen::VectorXd& positions_m);
  void visit(int tet, const Sweep& sweep, const Eigen::VectorXd& positions_m);
  void process_edge(int edge, const Sweep& sweep, const Eigen::VectorXd& positions_m);
  void push_unvisited(int tet);
  void find_next_active(const Blade& blade, const Eigen::VectorXd& positions_m);
  void complete_touched_tets(CutStepReport& report);

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
  std::vector<std::int8_t> m_tet_cut_count;     ///< sessions that cut the tet
  std::vector<int> m_tet_ignored_session;       ///< last session that reported an ignored cut
  std::vector<std::int64_t> m_edge_stamp;       ///< tested against the current sweep
  std::vector<int> m_edge_session;              ///< session whose crossing is recorded, -1 if none
  std::vector<double> m_edge_ratio;             ///< along {v0, v1}
  std::vector<std::int8_t> m_edge_upper_end;    ///< +1: v1 above the sweep, -1: v0, 0: unknown

  std::vector<int> m_active;
  std::vector<int> m_visited;     ///< algorithm 2's intersected list of this step
  std::vector<int> m_stack;       ///< explicit stack of the searches (no recursion)
  std::vector<int> m_seeds;       ///< tets of surface triangles the sweep crosses
  std::vector<int> m_new_edges;   ///< edges recorded this step
  std::vector<int> m_candidates;  ///< tets around them
  std::vector<TetCut> m_new_cuts;
  std::vector<SurfaceBvh::SegmentHit> m_hits;
  std::vector<int> m_box_triangles;
};

}  // namespace tissue
