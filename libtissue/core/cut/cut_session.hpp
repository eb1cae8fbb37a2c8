// CutSession: the scalpel's cutting as the tissue keeps it. Each step the blade sweeps its path
// through the volume (sub-sweeps of at most a few degrees of turn) and the tets it completes are
// handed to the caller to enrich; the cuts enriched are kept in order, batch by batch, so that a
// saved state's cuts can be replayed into a fresh tissue (check_history, replay).
#pragma once

#include "core/collide/lazy_surface_bvh.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/tool/tool_pose.hpp"

#include <functional>
#include <optional>
#include <span>
#include <vector>

namespace tissue {

/// What a step's sweep did, with wall times [s].
struct CutSweepReport {
  CutStepReport cut;            ///< the last sub-sweep's, with newly_cut_tets summed over all
  EnrichmentResult enrichment;  ///< summed over the sub-sweeps
  double cut_s = 0.0;           ///< volume cutter
  double enrich_s = 0.0;        ///< enrichment and in-place growth
};

/// Enriches one batch of cuts (`offsets_m` empty: live, from the state; else replayed with the recorded
/// offsets of the cut tets it makes) and returns what it made.
using ApplyCuts =
    std::function<EnrichmentResult(std::span<const TetCut> cuts, std::span<const std::vector<TetPositions>> offsets_m)>;

class CutSession {
 public:
  /// Cutting off (`enabled` false): no cutter is built and sweep() is never asked for. `mesh`,
  /// `adjacency` and `surface` outlive the session.
  CutSession(bool enabled, const TetMesh& mesh, const TetAdjacency& adjacency, const SurfaceMesh& surface,
             const CutterSettings& settings, double blade_length_m);

  [[nodiscard]] bool enabled() const { return m_cutter.has_value(); }
  /// Throws std::logic_error when cutting is off (no cutter is built then).
  [[nodiscard]] const VolumeCutter& cutter() const;
  /// The cutting edge of a pose: from the tip along the tool axis.
  [[nodiscard]] Blade blade(const ToolPose& pose) const;

  /// The blade swept from `previous` to `current` through the surface in `bvh`; each sub-sweep that
  /// completed tets has them enriched by `apply` (live) and recorded.
  CutSweepReport sweep(const ToolPose& previous, const ToolPose& current, const LazySurfaceBvh& bvh,
                       const ApplyCuts& apply);
  /// The scalpel stopped cutting (its mode changed, or cutting was switched off): a session in
  /// progress ends where the blade is (VolumeCutter::end_cut), and the tets it went into are
  /// enriched by `apply` and recorded as a sweep's are.
  CutSweepReport stop(const LazySurfaceBvh& bvh, const ApplyCuts& apply);
  /// Length of the blade of `tool` inside the tissue while it cuts [m] (0 otherwise): from the handle
  /// end of the edge, the first crossing of the mesh's surface (ids below `mesh_triangles`).
  [[nodiscard]] double blade_depth_m(const ToolPose& tool, const LazySurfaceBvh& bvh, int mesh_triangles) const;

  /// Records a batch of cuts enriched (a sweep's, or a replayed one).
  void record(std::span<const TetCut> cuts);
  /// Every cut enriched, in order, and where each batch ends in it.
  [[nodiscard]] const std::vector<TetCut>& history() const { return m_history; }
  [[nodiscard]] const std::vector<int>& batch_ends() const { return m_batch_ends; }
  [[nodiscard]] bool has_history(std::span<const TetCut> cuts, std::span<const int> batch_ends) const;
  /// Throws StateError unless `batch_ends` increase and end at cuts.size().
  static void check_history(std::span<const TetCut> cuts, std::span<const int> batch_ends);
  /// Replays a checked history into this session (nothing cut yet), batch by batch through `apply`
  /// with the offsets of the cut tets each makes. Throws StateError when the offsets do not match
  /// the cut tets made, or a cut cannot be replayed.
  void replay(std::span<const TetCut> cuts, std::span<const int> batch_ends,
              std::span<const std::vector<TetPositions>> offsets_m, const ApplyCuts& apply);

  /// The cutter's session (nothing without a cutter).
  void save(VolumeCutter::SessionState& state) const;
  /// Throws std::invalid_argument (nothing changed) for a session that does not fit the cutter.
  void restore(const VolumeCutter::SessionState& state);

 private:
  /// Enriches the cutter's new cuts (if any) through `apply`, records them, adds to `report`.
  void apply_new_cuts(const ApplyCuts& apply, CutSweepReport& report);

  std::optional<VolumeCutter> m_cutter;
  double m_blade_length_m;
  std::vector<TetCut> m_history;
  std::vector<int> m_batch_ends;
  mutable std::vector<SurfaceBvh::SegmentHit> m_blade_hits;  // scratch of blade_depth_m()
};

}  // namespace tissue
