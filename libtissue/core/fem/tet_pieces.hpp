// The pieces of a tet cut by several sessions (issue 21, the virtual-node algorithm: Molino, Bao and
// Fedkiw 2004; Sifakis, Der and Fedkiw 2007). Each cut of a tet is the plane through its crossings
// in the rest configuration (exact for a 1-3 split and for a planar stroke; the least-squares plane
// of a bent 2-2 quad). The first cut makes two pieces with its own exact fraction (part_volume);
// each later cut splits every piece it passes through (volume on both sides, however thin: the tets
// around a face must agree on its pieces), each side's fraction clamped to at least the smallest as
// the first cut's is (a piece under twice the smallest stays whole), and leaves the others as they
// were. A piece is then a convex cell: the tet clipped by the planes that bound it, each on one side.
#pragma once

#include "core/fem/convex_piece.hpp"
#include "core/fem/tet_cut.hpp"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace tissue {

/// Where a piece lies with respect to each of its tet's cuts (in the order applied, bit c for cut c).
struct PieceSides {
  std::uint32_t bounded = 0;  ///< bit c: cut c bounds the piece (split it or its parent)
  /// bit c: the piece lies above cut c; for a cut that does not bound it, the side of its plane that
  /// holds the piece (all of it but less than the smallest fraction)
  std::uint32_t above = 0;
  bool operator==(const PieceSides&) const = default;
};

struct TetPiece {
  PieceSides sides;
  double volume_fraction = 0.0;  ///< of the tet's rest volume; a tet's pieces add up to 1
  int parent = -1;               ///< index of the piece among the previous pieces it came from (-1: the uncut tet)
};

/// The plane of `cut` through its crossing points on the tet `rest_m`, oriented so that the vertices
/// with side +1 lie on its positive side.
CutPlane cut_plane(const std::array<Eigen::Vector3d, 4>& rest_m, const TetCut& cut);

/// The pieces after the last of `cuts` (all the tet's cuts, in order; at most MAX_PIECE_CUTS);
/// `previous`: the pieces of the cuts before it (empty for the first cut). Pieces keep their order;
/// a split piece becomes two, above first; a piece not split takes the side of the new plane that
/// holds it. Split fractions divide the piece's own fraction in the
/// ratio of the two sides' volumes, so the fractions keep adding up to 1.
std::vector<TetPiece> split_pieces(const std::array<Eigen::Vector3d, 4>& rest_m, std::span<const TetCut> cuts,
                                   std::span<const TetPiece> previous);

/// A piece's rest geometry: the tet clipped by its bounding planes (cap tags 4 + cut index).
ConvexPiece piece_geometry(const std::array<Eigen::Vector3d, 4>& rest_m, std::span<const TetCut> cuts,
                           const PieceSides& sides);

/// Whether local vertex j lies in the piece (on the piece's side of every cut of the tet).
bool vertex_in_piece(std::span<const TetCut> cuts, const PieceSides& sides, int j);

}  // namespace tissue
