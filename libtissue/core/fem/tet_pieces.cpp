// Pieces of a tet cut several times (see tet_pieces.hpp).
#include "core/fem/tet_pieces.hpp"

#include "core/mesh/topology.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

// Corners closer than this fraction of the tet's longest edge are one (clipping round-off).
constexpr double TOLERANCE_FRACTION = 1e-12;

}  // namespace

CutPlane cut_plane(const std::array<Eigen::Vector3d, 4>& rest_m, const TetCut& cut) {
  const double merge_m = TOLERANCE_FRACTION * largest_edge_m(rest_m);
  std::array<Eigen::Vector3d, 6> points;
  int count = 0;
  for (std::size_t e = 0; e < 6; ++e) {
    const double r = cut.edge_ratio[e];
    if (r < 0.0) continue;
    const Eigen::Vector3d p = (1.0 - r) * rest_m[static_cast<std::size_t>(TET_EDGES[e][0])] +
                              r * rest_m[static_cast<std::size_t>(TET_EDGES[e][1])];
    bool seen = false;
    for (int k = 0; k < count; ++k) seen = seen || (points[static_cast<std::size_t>(k)] - p).norm() <= merge_m;
    if (!seen) points[static_cast<std::size_t>(count++)] = p;
  }
  if (count < 3)
    throw std::invalid_argument("cut_plane: the cut of tet " + std::to_string(cut.tet) +
                                " has fewer than three points");
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int k = 0; k < count; ++k) centre += points[static_cast<std::size_t>(k)];
  centre /= count;
  // The crossing points held a margin off a vertex on the blade bunch around it: with fewer than three
  // such places (a vertex or an edge on the blade) their plane leans any way, parallel to the far
  // face for one vertex; the blade's own normal is the cut's.
  constexpr double SAME_PLACE_FRACTION = 1e-3;
  const double same_place_m = SAME_PLACE_FRACTION * largest_edge_m(rest_m);
  int places = 0;
  for (int k = 0; k < count; ++k) {
    bool seen = false;
    for (int m = 0; m < k; ++m) {
      seen = seen || (points[static_cast<std::size_t>(k)] - points[static_cast<std::size_t>(m)]).norm() <= same_place_m;
    }
    places += seen ? 0 : 1;
  }
  Eigen::Vector3d normal;
  if (places < 3 && cut.blade_normal.squaredNorm() > 0.0) {
    normal = cut.blade_normal;
  } else if (count == 3) {
    normal = (points[1] - points[0]).cross(points[2] - points[0]);
  } else {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (int k = 0; k < count; ++k) {
      const Eigen::Vector3d d = points[static_cast<std::size_t>(k)] - centre;
      scatter += d * d.transpose();
    }
    normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
  }
  normal.normalize();
  double lean = 0.0;  // which way the vertices above lie
  for (std::size_t i = 0; i < 4; ++i) lean += cut.side[i] * normal.dot(rest_m[i] - centre);
  if (lean < 0.0) normal = -normal;
  return CutPlane{normal, normal.dot(centre)};
}

ConvexPiece piece_geometry(const std::array<Eigen::Vector3d, 4>& rest_m, std::span<const TetCut> cuts,
                           const PieceSides& sides) {
  const double tolerance_m = TOLERANCE_FRACTION * largest_edge_m(rest_m);
  ConvexPiece piece = ConvexPiece::tet(rest_m);
  for (std::size_t c = 0; c < cuts.size() && !piece.empty(); ++c) {
    const std::uint32_t bit = 1u << c;
    if ((sides.bounded & bit) == 0) continue;
    piece = piece.clipped(cut_plane(rest_m, cuts[c]), (sides.above & bit) != 0, tolerance_m, 4 + static_cast<int>(c));
  }
  return piece;
}

bool vertex_in_piece(std::span<const TetCut> cuts, const PieceSides& sides, int j) {
  for (std::size_t c = 0; c < cuts.size(); ++c) {
    const std::uint32_t bit = 1u << c;
    if ((cuts[c].side[static_cast<std::size_t>(j)] > 0) != ((sides.above & bit) != 0)) return false;
  }
  return true;
}

std::vector<TetPiece> split_pieces(const std::array<Eigen::Vector3d, 4>& rest_m, std::span<const TetCut> cuts,
                                   std::span<const TetPiece> previous) {
  if (cuts.empty() || cuts.size() > static_cast<std::size_t>(MAX_PIECE_CUTS)) {
    throw std::invalid_argument("split_pieces: a tet takes 1 to " + std::to_string(MAX_PIECE_CUTS) + " cuts");
  }
  const TetCut& cut = cuts.back();
  if (cuts.size() == 1) {
    return {TetPiece{PieceSides{1u, 1u}, cut.volume_fraction_above, -1},
            TetPiece{PieceSides{1u, 0u}, 1.0 - cut.volume_fraction_above, -1}};
  }
  const std::size_t c = cuts.size() - 1;
  const std::uint32_t bit = 1u << c;
  const double tolerance_m = TOLERANCE_FRACTION * largest_edge_m(rest_m);
  const double tet_volume_m3 = std::abs(ConvexPiece::tet(rest_m).volume_m3());
  const CutPlane plane = cut_plane(rest_m, cut);
  const std::span<const TetCut> earlier = cuts.first(c);
  std::vector<TetPiece> pieces;
  pieces.reserve(2 * previous.size());
  for (std::size_t p = 0; p < previous.size(); ++p) {
    const TetPiece& old = previous[p];
    const ConvexPiece geometry = piece_geometry(rest_m, earlier, old.sides);
    const double above_m3 = std::abs(geometry.clipped(plane, true, tolerance_m).volume_m3());
    const double below_m3 = std::abs(geometry.clipped(plane, false, tolerance_m).volume_m3());
    // Split wherever the plane passes through the piece (both sides hold volume): a sliver left whole
    // here would be cut in the tet beside it, and the two tets' pieces would disagree on their shared
    // face (the weld, issue 43). Each side's fraction is at least the smallest, as the first cut's
    // are clamped; a piece too small for two such sides stays whole.
    const double smallest = cut.min_volume_fraction;
    const double touching_m3 = SMALLEST_MIN_VOLUME_FRACTION * tet_volume_m3;
    if (above_m3 <= touching_m3 || below_m3 <= touching_m3 || old.volume_fraction < 2.0 * smallest) {
      const std::uint32_t side = above_m3 >= below_m3 ? bit : 0u;
      pieces.push_back(
          TetPiece{PieceSides{old.sides.bounded, old.sides.above | side}, old.volume_fraction, static_cast<int>(p)});
      continue;
    }
    const double above_fraction =
        std::clamp(old.volume_fraction * above_m3 / (above_m3 + below_m3), smallest, old.volume_fraction - smallest);
    pieces.push_back(
        TetPiece{PieceSides{old.sides.bounded | bit, old.sides.above | bit}, above_fraction, static_cast<int>(p)});
    pieces.push_back(TetPiece{PieceSides{old.sides.bounded | bit, old.sides.above},
                              old.volume_fraction - above_fraction, static_cast<int>(p)});
  }
  return pieces;
}

}  // namespace tissue
