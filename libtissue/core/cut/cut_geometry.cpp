// Complete-cut classification and exact part volumes of one cut tet (see cut_geometry.hpp).
#include "core/cut/cut_geometry.hpp"

#include "core/mesh/tet_mesh.hpp"
#include "core/mesh/topology.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace tissue {
namespace {

/// The splits of four vertices into two non-empty groups, each named by one of its groups (bit i =
/// local vertex i): the four 1-3 splits, then the three 2-2 splits.
constexpr std::array<unsigned, 7> SPLITS = {0b0001u, 0b0010u, 0b0100u, 0b1000u, 0b0011u, 0b0101u, 0b1001u};
constexpr unsigned ALL_VERTICES = 0b1111u;

bool in_group(unsigned group, int vertex) { return ((group >> static_cast<unsigned>(vertex)) & 1u) != 0u; }

/// Signed volume of the cone from `origin` over the triangle (a, b, c): one term of the divergence theorem.
double cone_volume(const Eigen::Vector3d& origin, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                   const Eigen::Vector3d& c) {
  return (a - origin).dot((b - origin).cross(c - origin)) / 6.0;
}

/// Where the cut meets one edge between the groups.
struct CutPoint {
  int id = -1;         ///< 0..3: the cut passes through that local vertex; 4 + k: interior of edge k
  double ratio = 0.0;  ///< along the local edge, as TetCut::edge_ratio
};

/// The cut points of a split, or nothing when the crossings do not cut the tet along it.
struct SplitPoints {
  std::array<CutPoint, 6> points{};  ///< by local edge; id -1 for edges within a group
  int distinct = 0;                  ///< number of distinct cut points
};

/// Classified crossings of one tet: interior crossings and the vertices the cut passes through.
struct CrossingPattern {
  std::array<bool, 6> interior{};
  std::array<bool, 4> through{};
  unsigned off_cut = 0;  ///< vertices that are not through-vertices (bit mask)
};

CrossingPattern classify_crossings(const TetEdgeCrossings& crossings, double vertex_snap_fraction) {
  CrossingPattern pattern;
  for (std::size_t k = 0; k < 6; ++k) {
    const double ratio = crossings.ratio[k];
    if (!(ratio >= 0.0)) continue;  // not crossed
    const auto& edge = TET_EDGES[k];
    if (ratio <= vertex_snap_fraction) {
      pattern.through[static_cast<std::size_t>(edge[0])] = true;
    } else if (ratio >= 1.0 - vertex_snap_fraction) {
      pattern.through[static_cast<std::size_t>(edge[1])] = true;
    } else {
      pattern.interior[k] = true;
    }
  }
  for (int v = 0; v < 4; ++v) {
    if (!pattern.through[static_cast<std::size_t>(v)]) pattern.off_cut |= 1u << static_cast<unsigned>(v);
  }
  return pattern;
}

/// The cut points of `group` against the rest, if the pattern cuts the tet along this split.
std::optional<SplitPoints> split_points(const CrossingPattern& pattern, const TetEdgeCrossings& crossings,
                                        unsigned group) {
  SplitPoints split;
  std::array<bool, 10> seen{};
  for (std::size_t k = 0; k < 6; ++k) {
    const int i = TET_EDGES[k][0];
    const int j = TET_EDGES[k][1];
    if (in_group(group, i) == in_group(group, j)) {
      if (pattern.interior[k]) return std::nullopt;  // a crossing inside one part
      continue;
    }
    CutPoint& point = split.points[k];
    if (pattern.interior[k]) {
      point = {4 + static_cast<int>(k), crossings.ratio[k]};
    } else if (pattern.through[static_cast<std::size_t>(i)]) {
      point = {i, 0.0};
    } else if (pattern.through[static_cast<std::size_t>(j)]) {
      point = {j, 1.0};
    } else {
      return std::nullopt;  // an edge between the parts that the cut does not reach
    }
    if (!seen[static_cast<std::size_t>(point.id)]) {
      seen[static_cast<std::size_t>(point.id)] = true;
      ++split.distinct;
    }
  }
  if (split.distinct < 3) return std::nullopt;  // the cut only touches a vertex or runs along an edge
  return split;
}

/// The first split that the pattern cuts: preferably one with an off-cut vertex on each side,
/// else the off-cut vertices against the through-vertices (a cut along a face).
std::optional<std::pair<unsigned, SplitPoints>> find_split(const CrossingPattern& pattern,
                                                           const TetEdgeCrossings& crossings) {
  for (const unsigned group : SPLITS) {
    const bool off_cut_on_both_sides =
        (group & pattern.off_cut) != 0u && (~group & ALL_VERTICES & pattern.off_cut) != 0u;
    if (!off_cut_on_both_sides) continue;
    if (auto split = split_points(pattern, crossings, group)) return std::make_pair(group, *split);
  }
  if (pattern.off_cut != 0u && pattern.off_cut != ALL_VERTICES) {
    if (auto split = split_points(pattern, crossings, pattern.off_cut)) return std::make_pair(pattern.off_cut, *split);
  }
  return std::nullopt;
}

/// True when `group` lies above the cut: the majority of the crossed edges between the groups
/// have their upper end in it (a tie: the group holding local vertex 0).
bool group_is_above(unsigned group, const TetEdgeCrossings& crossings, const SplitPoints& split) {
  int votes = 0;
  for (std::size_t k = 0; k < 6; ++k) {
    if (split.points[k].id < 0 || !(crossings.ratio[k] >= 0.0) || crossings.upper_end[k] == 0) continue;
    const int upper = crossings.upper_end[k] > 0 ? TET_EDGES[k][1] : TET_EDGES[k][0];
    votes += in_group(group, upper) ? 1 : -1;
  }
  return votes != 0 ? votes > 0 : in_group(group, 0);
}

}  // namespace

double part_volume(const std::array<Eigen::Vector3d, 4>& x, unsigned group,
                   const std::array<Eigen::Vector3d, 6>& cut_points_m) {
  const Eigen::Vector3d origin = 0.25 * (x[0] + x[1] + x[2] + x[3]);  // near the tet: small round-off
  double volume = 0.0;
  // The cut surface, outward from the part, as a loop over cut points: from the cut point on edge
  // k the loop goes on to the one on edge cut_loop_next[k].
  std::array<int, 6> cut_loop_next{-1, -1, -1, -1, -1, -1};
  for (const auto& face : TET_FACES) {
    // The face's share of the part: its group vertices and the cut points on edges leaving the
    // group, in the face's outward winding (a convex polygon of at most 4 points).
    std::array<Eigen::Vector3d, 4> polygon;
    std::array<int, 4> polygon_edge{};  // local edge of a cut point, -1 for a vertex
    int size = 0;
    for (std::size_t m = 0; m < 3; ++m) {
      const int a = face[m];
      const int b = face[(m + 1) % 3];
      if (in_group(group, a)) {
        polygon[static_cast<std::size_t>(size)] = x[static_cast<std::size_t>(a)];
        polygon_edge[static_cast<std::size_t>(size++)] = -1;
      }
      if (in_group(group, a) != in_group(group, b)) {
        const int k = local_edge(a, b);
        polygon[static_cast<std::size_t>(size)] = cut_points_m[static_cast<std::size_t>(k)];
        polygon_edge[static_cast<std::size_t>(size++)] = k;
      }
    }
    for (int m = 1; m + 1 < size; ++m) {
      volume += cone_volume(origin, polygon[0], polygon[static_cast<std::size_t>(m)],
                            polygon[static_cast<std::size_t>(m + 1)]);
    }
    for (int m = 0; m < size; ++m) {
      const int from = polygon_edge[static_cast<std::size_t>(m)];
      const int to = polygon_edge[static_cast<std::size_t>((m + 1) % size)];
      if (from >= 0 && to >= 0) cut_loop_next[static_cast<std::size_t>(to)] = from;  // the cut runs the other way
    }
  }
  std::array<int, 4> loop{};
  int loop_size = 0;
  const auto first = std::find_if(cut_loop_next.begin(), cut_loop_next.end(), [](int k) { return k >= 0; });
  if (first == cut_loop_next.end()) return volume;  // group 0 or 15: no cut
  for (int k = static_cast<int>(first - cut_loop_next.begin()); loop_size < 4;) {
    loop[static_cast<std::size_t>(loop_size++)] = k;
    k = cut_loop_next[static_cast<std::size_t>(k)];
    if (k == loop[0] || k < 0) break;
  }
  const auto point = [&](int m) -> const Eigen::Vector3d& {
    return cut_points_m[static_cast<std::size_t>(loop[static_cast<std::size_t>(m)])];
  };
  if (loop_size == 3) {
    volume += cone_volume(origin, point(0), point(1), point(2));
  } else if ((point(0) - point(2)).squaredNorm() <= (point(1) - point(3)).squaredNorm()) {
    volume += cone_volume(origin, point(0), point(1), point(2)) + cone_volume(origin, point(0), point(2), point(3));
  } else {
    volume += cone_volume(origin, point(1), point(2), point(3)) + cone_volume(origin, point(1), point(3), point(0));
  }
  return volume;
}

std::optional<TetCut> classify_tet_cut(const std::array<Eigen::Vector3d, 4>& rest_m, const TetEdgeCrossings& crossings,
                                       double vertex_snap_fraction, double min_volume_fraction) {
  const CrossingPattern pattern = classify_crossings(crossings, vertex_snap_fraction);
  const auto found = find_split(pattern, crossings);
  if (!found) return std::nullopt;
  const auto& [group, split] = *found;

  TetCut cut;
  std::array<Eigen::Vector3d, 6> cut_points;
  for (std::size_t k = 0; k < 6; ++k) {
    const CutPoint& point = split.points[k];
    if (point.id < 0) continue;
    const double r = point.ratio;
    cut_points[k] = (1.0 - r) * rest_m[static_cast<std::size_t>(TET_EDGES[k][0])] +
                    r * rest_m[static_cast<std::size_t>(TET_EDGES[k][1])];
    cut.edge_ratio[k] = r;
  }
  const bool above = group_is_above(group, crossings, split);
  for (int v = 0; v < 4; ++v) {
    cut.side[static_cast<std::size_t>(v)] = in_group(group, v) == above ? std::int8_t{1} : std::int8_t{-1};
  }
  const double volume_m3 = signed_tet_volume(rest_m[0], rest_m[1], rest_m[2], rest_m[3]);
  const double group_fraction = part_volume(rest_m, group, cut_points) / volume_m3;
  double fraction_above = above ? group_fraction : 1.0 - group_fraction;
  if (!std::isfinite(fraction_above)) fraction_above = 0.5;  // a degenerate rest tet (never after loading)
  cut.volume_fraction_above = std::clamp(fraction_above, min_volume_fraction, 1.0 - min_volume_fraction);
  return cut;
}

TetCut cut_from_sides(const std::array<Eigen::Vector3d, 4>& rest_m, const std::array<std::int8_t, 4>& side,
                      const std::array<double, 6>& ratio, double end_margin, double min_volume_fraction) {
  TetCut cut;
  cut.side = side;
  unsigned above = 0u;
  for (int v = 0; v < 4; ++v) {
    if (side[static_cast<std::size_t>(v)] > 0) above |= 1u << static_cast<unsigned>(v);
  }
  std::array<Eigen::Vector3d, 6> cut_points;
  for (std::size_t k = 0; k < 6; ++k) {
    if (in_group(above, TET_EDGES[k][0]) == in_group(above, TET_EDGES[k][1])) continue;
    // The volume from where the blade passed (a vertex on the blade leaves its part no volume);
    // the cut points held end_margin off the ends, so that they are distinct.
    const double exact = std::clamp(ratio[k], 0.0, 1.0);
    cut_points[k] = (1.0 - exact) * rest_m[static_cast<std::size_t>(TET_EDGES[k][0])] +
                    exact * rest_m[static_cast<std::size_t>(TET_EDGES[k][1])];
    cut.edge_ratio[k] = std::clamp(ratio[k], end_margin, 1.0 - end_margin);
  }
  const double volume_m3 = signed_tet_volume(rest_m[0], rest_m[1], rest_m[2], rest_m[3]);
  double fraction_above = part_volume(rest_m, above, cut_points) / volume_m3;
  if (!std::isfinite(fraction_above)) fraction_above = 0.5;  // a degenerate rest tet (never after loading)
  cut.volume_fraction_above = std::clamp(fraction_above, min_volume_fraction, 1.0 - min_volume_fraction);
  return cut;
}

}  // namespace tissue
