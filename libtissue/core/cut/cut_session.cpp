// CutSession (see cut_session.hpp).
#include "core/cut/cut_session.hpp"

#include "core/state_error.hpp"
#include "core/wall_clock.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {

namespace {

// The largest turn of the blade one cutter sweep covers (its two triangles span the ruled surface
// of a turning segment to within ~ L (1 - cos(angle / 2)), 0.1 mm for a 3 cm blade at 5 degrees).
constexpr double MAX_SWEEP_ANGLE_RAD = 5.0 * 3.14159265358979323846 / 180.0;

int sweep_substeps(const ToolPose& from, const ToolPose& to) {
  const double angle_rad = from.orientation.angularDistance(to.orientation);
  return std::max(1, static_cast<int>(std::ceil(angle_rad / MAX_SWEEP_ANGLE_RAD)));
}

bool same_cut(const TetCut& a, const TetCut& b) {
  return a.tet == b.tet && a.cut_id == b.cut_id && a.side == b.side &&
         a.volume_fraction_above == b.volume_fraction_above && a.edge_ratio == b.edge_ratio &&
         a.min_volume_fraction == b.min_volume_fraction && a.blade_normal == b.blade_normal;
}

}  // namespace

CutSession::CutSession(bool enabled, const TetMesh& mesh, const TetAdjacency& adjacency, const SurfaceMesh& surface,
                       const CutterSettings& settings, double blade_length_m)
    : m_blade_length_m(blade_length_m) {
  if (enabled) m_cutter.emplace(mesh, adjacency, surface, settings);
}

const VolumeCutter& CutSession::cutter() const {
  if (!m_cutter) throw std::logic_error("Tissue::cutter: cutting is off in this scene (no cutter was built)");
  return *m_cutter;
}

Blade CutSession::blade(const ToolPose& pose) const {
  return Blade{pose.tip_position_m, pose.tip_position_m + m_blade_length_m * tool_axis(pose.orientation)};
}

CutSweepReport CutSession::sweep(const ToolPose& previous, const ToolPose& current, const LazySurfaceBvh& bvh,
                                 const ApplyCuts& apply) {
  // The blade sweeps two triangles per cutter step; a turning blade's surface is curved, so the
  // step is cut in sub-sweeps of at most MAX_SWEEP_ANGLE_RAD, along the path the tool took.
  CutSweepReport report;
  const int substeps = sweep_substeps(previous, current);
  ToolPose from = previous;
  for (int k = 1; k <= substeps; ++k) {
    const double fraction = static_cast<double>(k) / substeps;
    ToolPose to = current;
    if (k < substeps) {
      to.tip_position_m = previous.tip_position_m + fraction * (current.tip_position_m - previous.tip_position_m);
      to.orientation = previous.orientation.slerp(fraction, current.orientation).normalized();
    }
    const auto cut_start = std::chrono::steady_clock::now();
    const CutStepReport cut = m_cutter->step(blade(from), blade(to), bvh.positions_m(), bvh.fitted());
    const int newly_cut = report.cut.newly_cut_tets + cut.newly_cut_tets;
    report.cut = cut;
    report.cut.newly_cut_tets = newly_cut;
    report.cut_s += seconds_since(cut_start);
    from = to;
    apply_new_cuts(apply, report);
  }
  return report;
}

CutSweepReport CutSession::stop(const LazySurfaceBvh& bvh, const ApplyCuts& apply) {
  CutSweepReport report;
  if (!m_cutter) return report;
  // Also after a session that ended itself (then nothing is cut): the next is a new stroke.
  const auto cut_start = std::chrono::steady_clock::now();
  // The positions only for an open session (end_cut reads them then): a step with the tool away
  // brings none up to date (SurfaceViews writes them when first read).
  report.cut = m_cutter->cutting() ? m_cutter->end_cut(bvh.positions_m()) : m_cutter->end_cut(Eigen::VectorXd());
  report.cut_s = seconds_since(cut_start);
  apply_new_cuts(apply, report);
  return report;
}

void CutSession::apply_new_cuts(const ApplyCuts& apply, CutSweepReport& report) {
  if (m_cutter->new_cuts().empty()) return;
  const auto enrich_start = std::chrono::steady_clock::now();
  const EnrichmentResult enriched = apply(m_cutter->new_cuts(), {});
  record(m_cutter->new_cuts());
  report.enrichment.new_cut_tets += enriched.new_cut_tets;
  report.enrichment.new_enriched_dofs += enriched.new_enriched_dofs;
  report.enrichment.matrix_relayout = report.enrichment.matrix_relayout || enriched.matrix_relayout;
  report.enrich_s += seconds_since(enrich_start);
}

double CutSession::blade_depth_m(const ToolPose& tool, const LazySurfaceBvh& bvh, int mesh_triangles) const {
  if (tool.mode != ToolMode::scalpel || !m_cutter || !m_cutter->cutting()) return 0.0;
  // The edge runs from the tip along the tool axis; from the handle end (outside while a cut
  // starts), the first crossing of the mesh's own surface is where the blade enters the tissue.
  const Eigen::Vector3d handle_m = tool.tip_position_m + m_blade_length_m * tool_axis(tool.orientation);
  bvh.fitted().intersect_segment(handle_m, tool.tip_position_m, bvh.positions_m(), m_blade_hits);
  for (const SurfaceBvh::SegmentHit& hit : m_blade_hits) {
    if (hit.triangle < mesh_triangles) return (1.0 - hit.segment_parameter) * m_blade_length_m;
  }
  return m_blade_length_m;  // no crossing while cutting: the whole edge is inside
}

void CutSession::record(std::span<const TetCut> cuts) {
  m_history.insert(m_history.end(), cuts.begin(), cuts.end());
  m_batch_ends.push_back(static_cast<int>(m_history.size()));
}

bool CutSession::has_history(std::span<const TetCut> cuts, std::span<const int> batch_ends) const {
  return std::equal(batch_ends.begin(), batch_ends.end(), m_batch_ends.begin(), m_batch_ends.end()) &&
         std::equal(cuts.begin(), cuts.end(), m_history.begin(), m_history.end(), same_cut);
}

void CutSession::check_history(std::span<const TetCut> cuts, std::span<const int> batch_ends) {
  int previous_end = 0;
  for (const int end : batch_ends) {
    if (end <= previous_end) throw StateError("the state's cut batches are not increasing");
    previous_end = end;
  }
  if (static_cast<size_t>(previous_end) != cuts.size()) {
    throw StateError("the state's cut batches do not add up to its cuts");
  }
}

void CutSession::replay(std::span<const TetCut> cuts, std::span<const int> batch_ends,
                        std::span<const std::vector<TetPositions>> offsets_m, const ApplyCuts& apply) {
  try {
    // A batch makes a cut tet per cut and may remake others (their pieces' ghosts regrouped): it
    // takes the offsets of as many cut tets as it made.
    int begin = 0;
    size_t offsets_used = 0;
    for (const int end : batch_ends) {
      const auto first = static_cast<size_t>(begin);
      const auto count = static_cast<size_t>(end - begin);
      if (offsets_used + count > offsets_m.size()) throw StateError("the state has too few enrichment offsets");
      const std::span<const TetCut> batch = cuts.subspan(first, count);
      const EnrichmentResult made = apply(batch, offsets_m.subspan(offsets_used));
      record(batch);
      offsets_used += static_cast<size_t>(made.new_cut_tets);
      begin = end;
    }
    if (offsets_used != offsets_m.size()) throw StateError("the state has more enrichment offsets than cut tets");
  } catch (const std::invalid_argument& error) {
    throw StateError(std::string("the state's cuts cannot be replayed: ") + error.what());
  }
}

void CutSession::save(VolumeCutter::SessionState& state) const {
  if (m_cutter) m_cutter->save(state);
}

void CutSession::restore(const VolumeCutter::SessionState& state) {
  if (m_cutter) m_cutter->restore(state);
}

}  // namespace tissue
