// Where a rest point lies against a piece of a cut tet (CutTetGeometry): the one rule the render
// surface's locating and the tet skin's weld share.
#pragma once

#include "core/fem/deformable_body.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cstddef>
#include <limits>

namespace tissue {

/// How far rest point `p` lies outside piece `piece` of `geometry` (the largest distance beyond the
/// planes that bound it; <= 0 inside). [m]
inline double outside_piece_m(const CutTetGeometry& geometry, std::size_t piece, const Eigen::Vector3d& p) {
  const PieceSides& sides = geometry.pieces[piece].sides;
  double outside = -std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < geometry.cuts.size(); ++c) {
    if ((sides.bounded & (1u << c)) == 0) continue;
    const double toward_inside = (sides.above & (1u << c)) != 0 ? 1.0 : -1.0;
    outside = std::max(outside, -toward_inside * geometry.planes[c].signed_distance(p));
  }
  return outside;
}

}  // namespace tissue
