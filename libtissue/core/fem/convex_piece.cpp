// ConvexPiece (see convex_piece.hpp).
#include "core/fem/convex_piece.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace tissue {
namespace {

/// Newell's normal of a polygon (twice its area along the normal; counter-clockwise: outward).
Eigen::Vector3d newell_normal(const Eigen::Vector3d* corners, int count) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (int i = 0; i < count; ++i) n += corners[i].cross(corners[(i + 1) % count]);
  return n;
}

/// Signed volume of the cone from `origin` over the triangle (a, b, c).
double cone_volume(const Eigen::Vector3d& origin, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                   const Eigen::Vector3d& c) {
  return (a - origin).dot((b - origin).cross(c - origin)) / 6.0;
}

}  // namespace

void ConvexPiece::add_face(const Eigen::Vector3d* corners, int count, int tag) {
  if (m_face_count == MAX_PIECE_FACES || count > MAX_FACE_CORNERS) {
    throw std::length_error("ConvexPiece: more than " + std::to_string(MAX_PIECE_CUTS) + " cut planes");
  }
  const auto f = static_cast<std::size_t>(m_face_count++);
  m_corner_count[f] = count;
  m_face_tag[f] = tag;
  for (int k = 0; k < count; ++k) m_corners[f][static_cast<std::size_t>(k)] = corners[k];
}

ConvexPiece ConvexPiece::tet(const std::array<Eigen::Vector3d, 4>& x) {
  const bool positive = (x[1] - x[0]).dot((x[2] - x[0]).cross(x[3] - x[0])) > 0.0;
  // Faces opposite each vertex, counter-clockwise from outside for a positively oriented tet.
  constexpr std::array<std::array<int, 3>, 4> FACES = {{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};
  ConvexPiece piece;
  for (int tag = 0; tag < 4; ++tag) {
    const auto& face = FACES[static_cast<std::size_t>(tag)];
    std::array<Eigen::Vector3d, 3> corners{x[static_cast<std::size_t>(face[0])], x[static_cast<std::size_t>(face[1])],
                                           x[static_cast<std::size_t>(face[2])]};
    if (!positive) std::swap(corners[1], corners[2]);
    piece.add_face(corners.data(), 3, tag);
  }
  return piece;
}

ConvexPiece ConvexPiece::clipped(const CutPlane& plane, bool above, double tolerance_m, int cap_tag) const {
  const double normal_length = plane.normal.norm();
  const Eigen::Vector3d unit = plane.normal / normal_length;
  const double sign = above ? 1.0 : -1.0;
  // Distance into the kept side.
  const auto kept_distance = [&](const Eigen::Vector3d& x) { return sign * plane.signed_distance(x) / normal_length; };

  ConvexPiece out;
  std::array<Eigen::Vector3d, 2 * MAX_PIECE_FACES + 2 * MAX_FACE_CORNERS> cap{};
  int cap_count = 0;
  bool cap_is_a_face = false;
  const auto add_cap_point = [&](const Eigen::Vector3d& p) {
    for (int k = 0; k < cap_count; ++k) {
      if ((cap[static_cast<std::size_t>(k)] - p).norm() <= tolerance_m) return;
    }
    if (cap_count < static_cast<int>(cap.size())) cap[static_cast<std::size_t>(cap_count++)] = p;
  };

  for (int f = 0; f < m_face_count; ++f) {
    const int n = corner_count(f);
    std::array<Eigen::Vector3d, MAX_FACE_CORNERS + 1> kept{};
    int k = 0;
    bool all_on_plane = true;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d& a = corner(f, i);
      const Eigen::Vector3d& b = corner(f, (i + 1) % n);
      const double da = kept_distance(a), db = kept_distance(b);
      if (da >= -tolerance_m) {
        if (k <= MAX_FACE_CORNERS) kept[static_cast<std::size_t>(k)] = a;
        ++k;
        if (da <= tolerance_m) {
          add_cap_point(a);
        } else {
          all_on_plane = false;
        }
      } else {
        all_on_plane = false;
      }
      if ((da > tolerance_m && db < -tolerance_m) || (da < -tolerance_m && db > tolerance_m)) {
        const Eigen::Vector3d p = a + (b - a) * (da / (da - db));
        if (k <= MAX_FACE_CORNERS) kept[static_cast<std::size_t>(k)] = p;
        ++k;
        add_cap_point(p);
      }
    }
    if (k > MAX_FACE_CORNERS) throw std::length_error("ConvexPiece: a face with too many corners");
    if (k < 3) continue;
    if (all_on_plane) {
      // A face lying in the plane: it is the cap if it faces the side cut away; otherwise the piece
      // lies on that side and nothing is kept.
      if (sign * newell_normal(m_corners[static_cast<std::size_t>(f)].data(), n).dot(unit) < 0.0) {
        out.add_face(kept.data(), k, face_tag(f));
        cap_is_a_face = true;
      }
      continue;
    }
    out.add_face(kept.data(), k, face_tag(f));
  }
  if (!cap_is_a_face && cap_count >= 3 && out.m_face_count > 0) {
    // The cap's corners in order around their centroid, counter-clockwise seen from the side cut away
    // (its outward normal is -sign n).
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int k = 0; k < cap_count; ++k) centre += cap[static_cast<std::size_t>(k)];
    centre /= cap_count;
    const Eigen::Vector3d outward = -sign * unit;
    const Eigen::Vector3d u = outward.unitOrthogonal();
    const Eigen::Vector3d v = outward.cross(u);
    std::array<std::pair<double, int>, cap.size()> order{};
    for (int k = 0; k < cap_count; ++k) {
      const Eigen::Vector3d d = cap[static_cast<std::size_t>(k)] - centre;
      order[static_cast<std::size_t>(k)] = {std::atan2(d.dot(v), d.dot(u)), k};
    }
    std::sort(order.begin(), order.begin() + cap_count);
    std::array<Eigen::Vector3d, cap.size()> sorted{};
    for (int k = 0; k < cap_count; ++k) {
      sorted[static_cast<std::size_t>(k)] = cap[static_cast<std::size_t>(order[static_cast<std::size_t>(k)].second)];
    }
    if (cap_count > MAX_FACE_CORNERS) throw std::length_error("ConvexPiece: a cap with too many corners");
    out.add_face(sorted.data(), cap_count, cap_tag);
  }
  if (out.m_face_count < 4 || !(out.volume_m3() > 0.0)) return ConvexPiece{};
  return out;
}

double ConvexPiece::volume_m3() const {
  if (empty()) return 0.0;
  const Eigen::Vector3d& origin = corner(0, 0);
  double volume = 0.0;
  for (int f = 0; f < m_face_count; ++f) {
    for (int k = 1; k + 1 < corner_count(f); ++k) volume += cone_volume(origin, corner(f, 0), corner(f, k), corner(f, k + 1));
  }
  return volume;
}

Eigen::Vector3d ConvexPiece::centroid_m() const {
  if (empty()) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d& origin = corner(0, 0);
  double volume = 0.0;
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  for (int f = 0; f < m_face_count; ++f) {
    for (int k = 1; k + 1 < corner_count(f); ++k) {
      const double v = cone_volume(origin, corner(f, 0), corner(f, k), corner(f, k + 1));
      volume += v;
      moment += v * (origin + corner(f, 0) + corner(f, k) + corner(f, k + 1)) / 4.0;
    }
  }
  return volume != 0.0 ? (moment / volume).eval() : origin;
}

void arrangement_cells(const std::array<Eigen::Vector3d, 4>& x, std::span<const CutPlane> planes, double tolerance_m,
                       std::vector<PieceCell>& cells, std::vector<PieceCell>& scratch) {
  if (planes.size() > static_cast<std::size_t>(MAX_PIECE_CUTS)) {
    throw std::length_error("arrangement_cells: more than " + std::to_string(MAX_PIECE_CUTS) + " cut planes");
  }
  cells.clear();
  cells.push_back(PieceCell{ConvexPiece::tet(x), 0u});
  for (std::size_t c = 0; c < planes.size(); ++c) {
    scratch.clear();
    const std::uint32_t bit = 1u << static_cast<unsigned>(c);
    for (const PieceCell& cell : cells) {
      ConvexPiece above = cell.piece.clipped(planes[c], true, tolerance_m, 4 + static_cast<int>(c));
      ConvexPiece below = cell.piece.clipped(planes[c], false, tolerance_m, 4 + static_cast<int>(c));
      if (!above.empty()) scratch.push_back(PieceCell{std::move(above), cell.above | bit});
      if (!below.empty()) scratch.push_back(PieceCell{std::move(below), cell.above});
    }
    std::swap(cells, scratch);
  }
}

}  // namespace tissue
