// TetCut: how one cutting session cut one tet completely, as the volume cutter hands it to the XFEM
// (dissertation 3.3, 4.3.2). A tet may be cut by several sessions, one TetCut each (issue 21).
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>

namespace tissue {

/// The default smallest volume fraction of a cut piece (CutterSettings::min_volume_fraction).
inline constexpr double DEFAULT_MIN_VOLUME_FRACTION = 1e-3;
/// The floor of CutterSettings::min_volume_fraction (and of a TetCut's, checked when a body is cut).
/// Below it a part's ghost unknowns weigh ~1e-16 of their tet: a capped PCG solve moves them freely
/// and the next enrichment gives them mass, so the energy jumps (tests/extremes: 5.7 times the work
/// put in at 1e-300; bounded at 1e-12); at 5e-324 their mass and stiffness are 0 and the system singular.
inline constexpr double SMALLEST_MIN_VOLUME_FRACTION = 1e-12;

struct TetCut {
  int tet = -1;
  /// Which cutting session (blade entry to blade exit) made the cut; enriched DOFs are per session.
  int cut_id = 0;
  /// H_i of each local vertex of the tet: +1 above the cut, -1 below (dissertation eq. 3.14).
  /// Both signs occur.
  std::array<std::int8_t, 4> side{};
  /// V_a / V, the fraction of the rest volume above the cut (part a), exact for the cut surface
  /// through the edge intersection points, clamped to [min_volume_fraction, 1 - min_volume_fraction].
  double volume_fraction_above = 0.5;
  /// Where the cut crosses local edge k (TET_EDGES[k] = {i, j}): the point is
  /// (1 - r) X_i + r X_j in the rest configuration; -1 for an edge the cut does not cross.
  std::array<double, 6> edge_ratio{-1.0, -1.0, -1.0, -1.0, -1.0, -1.0};
  /// The cutter's smallest piece (CutterSettings::min_volume_fraction): a later cut of the tet
  /// splits a piece only if both sides keep at least this fraction of the tet (split_pieces).
  double min_volume_fraction = DEFAULT_MIN_VOLUME_FRACTION;
  /// The blade's plane's unit normal when the cutter made the cut (zero: not known, as for a cut given
  /// by hand). It orients the cut's plane where the crossing points cannot (cut_plane).
  Eigen::Vector3d blade_normal = Eigen::Vector3d::Zero();
};

}  // namespace tissue
