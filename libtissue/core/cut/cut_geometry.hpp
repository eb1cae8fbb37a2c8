// Geometry of one cut tet (dissertation 3.3, 4.3.2): from where the blade's sweep crossed the
// six edges of a tet, decide whether the tet is cut completely, which vertices lie above the
// cut, and the exact rest volume of each part. Pure functions; the VolumeCutter calls them.
#pragma once

#include "core/fem/tet_cut.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>

namespace tissue {

/// The recorded crossings of the six local edges (TET_EDGES) of one tet.
struct TetEdgeCrossings {
  /// Where local edge k = {i, j} was crossed: the point (1 - r) x_i + r x_j, r in [0, 1];
  /// negative for an edge that was not crossed.
  std::array<double, 6> ratio{-1.0, -1.0, -1.0, -1.0, -1.0, -1.0};
  /// Which end of edge k lies on the positive side of the sweep where it crossed: +1 for j,
  /// -1 for i, 0 unknown (edge parallel to the sweep).
  std::array<std::int8_t, 6> upper_end{};
};

/// Decides whether the crossings cut the tet completely and, if so, how (dissertation 4.3.2, one
/// cut per tet). A crossing within `vertex_snap_fraction` of an edge end passes through that
/// vertex (a "through-vertex"); others are interior crossings. The tet is cut when its vertices
/// split into two non-empty groups such that every edge between the groups is crossed in its
/// interior or ends at a through-vertex, no edge within a group is crossed in its interior, and
/// the cut surface has at least three distinct points (a blade that only touches a vertex or
/// runs along an edge does not cut). Splits that leave a vertex off the cut on both sides are
/// preferred; otherwise a cut along a face (all through-vertices on one side) is accepted, with
/// the volume fraction clamped.
///
/// The group "above" is the one that most crossed edges between the groups put above by their
/// `upper_end` (a tie, possible only for a folded sweep: the group holding local vertex 0).
/// `volume_fraction_above` is exact for the cut surface through the cut points (part_volume),
/// clamped to [min_volume_fraction, 1 - min_volume_fraction]; `edge_ratio` holds the cut point of
/// each edge between the groups (0 or 1 at a through-vertex) and -1 elsewhere. `tet` and `cut_id`
/// are left for the caller.
/// `rest_m`: the tet's four rest positions. Requires 0 <= vertex_snap_fraction < 0.5 and
/// 0 < min_volume_fraction < 0.5 (not checked here; CutterSettings validates them).
std::optional<TetCut> classify_tet_cut(const std::array<Eigen::Vector3d, 4>& rest_m, const TetEdgeCrossings& crossings,
                                       double vertex_snap_fraction, double min_volume_fraction);

/// The cut of a tet whose vertices' sides were decided (the cutter's per-vertex decisions, issue 41):
/// `side` +1 above, -1 below, both present; `ratio[k]` where the blade passed local edge k (along
/// TET_EDGES[k], in [0, 1]), read only for the edges between the sides and held at least
/// `end_margin` from either end there, so the cut points are distinct. The volume fraction is exact
/// for the cut surface through them (part_volume), clamped as classify_tet_cut clamps it.
TetCut cut_from_sides(const std::array<Eigen::Vector3d, 4>& rest_m, const std::array<std::int8_t, 4>& side,
                      const std::array<double, 6>& ratio, double end_margin, double min_volume_fraction);

/// Signed volume of the part of tet x (positive orientation: positive result) that holds the local
/// vertices in `group` (bit i set = vertex i; neither 0 nor 15), bounded by the tet's faces and the
/// cut surface through cut_points_m[k] on each local edge k between the group and the other vertices
/// (other entries are ignored). For a 2-2 split the four cut points are joined by two triangles
/// along the shorter diagonal. Exact by the divergence theorem: the parts for `group` and for its
/// complement always add up to the tet's volume.
double part_volume(const std::array<Eigen::Vector3d, 4>& x, unsigned group,
                   const std::array<Eigen::Vector3d, 6>& cut_points_m);

}  // namespace tissue
