// A convex piece of a tetrahedron: what is left of it between cut planes (issue 21, several cuts per
// tet). The pieces of a tet cut by several planar cuts are the cells of the planes' arrangement
// inside it, each convex: clip the tet by one plane after the other, keeping one side each time
// (Sutherland and Hodgman 1974, a polygon per face, plus the cap each plane leaves). Volumes by the
// divergence theorem, exact for the planes given (to rounding). Fixed capacity, no allocation: a
// tet and up to MAX_PIECE_CUTS planes.
#pragma once

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace tissue {

/// Cuts a convex piece can carry beyond the tet's own four faces.
inline constexpr int MAX_PIECE_CUTS = 8;
inline constexpr int MAX_PIECE_FACES = 4 + MAX_PIECE_CUTS;
/// A face of a tet clipped by k planes has at most 3 + k corners.
inline constexpr int MAX_FACE_CORNERS = 3 + MAX_PIECE_CUTS;

/// The plane n . x = offset; its positive side ("above") is n . x > offset. n need not be unit.
struct CutPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  [[nodiscard]] double signed_distance(const Eigen::Vector3d& x) const { return normal.dot(x) - offset; }
};

class ConvexPiece {
 public:
  /// The whole tet with corners `x` (either orientation; faces are made outward).
  static ConvexPiece tet(const std::array<Eigen::Vector3d, 4>& x);

  /// The part of this piece on one side of `plane` (`above`: its positive side), or an empty piece.
  /// Corners within `tolerance_m` of the plane count as on it. The cap the plane leaves gets the face
  /// tag `cap_tag`; clipped faces keep theirs. A piece that would exceed MAX_PIECE_FACES faces or
  /// MAX_FACE_CORNERS corners on a face throws std::length_error (more than MAX_PIECE_CUTS planes).
  [[nodiscard]] ConvexPiece clipped(const CutPlane& plane, bool above, double tolerance_m, int cap_tag = -1) const;

  [[nodiscard]] bool empty() const { return m_face_count == 0; }
  /// Volume by the divergence theorem [m^3]; 0 when empty.
  [[nodiscard]] double volume_m3() const;
  /// Centroid of the piece's volume [m] (empty piece: zero).
  [[nodiscard]] Eigen::Vector3d centroid_m() const;
  [[nodiscard]] int face_count() const { return m_face_count; }
  [[nodiscard]] int corner_count(int face) const { return m_corner_count[static_cast<std::size_t>(face)]; }
  /// Where face f lies: k in [0, 4) on the tet's face opposite its vertex k (TET_FACES' order), or the
  /// cap tag of the clip that made it.
  [[nodiscard]] int face_tag(int face) const { return m_face_tag[static_cast<std::size_t>(face)]; }
  /// Corner k of face f, counter-clockwise seen from outside.
  [[nodiscard]] const Eigen::Vector3d& corner(int face, int k) const {
    return m_corners[static_cast<std::size_t>(face)][static_cast<std::size_t>(k)];
  }

 private:
  void add_face(const Eigen::Vector3d* corners, int count, int tag);

  int m_face_count = 0;
  std::array<int, MAX_PIECE_FACES> m_corner_count{};
  std::array<int, MAX_PIECE_FACES> m_face_tag{};
  std::array<std::array<Eigen::Vector3d, MAX_FACE_CORNERS>, MAX_PIECE_FACES> m_corners{};
};

/// A cell of cut planes' arrangement inside a tet: bit c of `above` is set when the cell lies on the
/// positive side of plane c.
struct PieceCell {
  ConvexPiece piece;
  std::uint32_t above = 0;
};

/// The non-empty cells of `planes` (at most MAX_PIECE_CUTS) inside the tet `x`: the tet split by
/// every plane that passes through it, in turn. Their volumes add up to the tet's (to rounding).
/// `scratch`: work space; with capacity reserved neither vector allocates.
void arrangement_cells(const std::array<Eigen::Vector3d, 4>& x, std::span<const CutPlane> planes, double tolerance_m,
                       std::vector<PieceCell>& cells, std::vector<PieceCell>& scratch);

}  // namespace tissue
