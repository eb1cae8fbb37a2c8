// Whether a triangle surface is what a viewer needs (issue 43: the drawn tet skin welded): closed and
// consistently oriented, every edge (by its pair of point ids) with exactly one triangle each way;
// how many pieces (triangles joined through shared points); triangles naming a point twice.
#pragma once

#include <array>
#include <cstddef>
#include <map>
#include <numeric>
#include <set>
#include <utility>
#include <vector>

namespace tissue::test_support {

struct SurfaceCheck {
  int open_edges = 0;  ///< edges with other than one triangle each way
  int pieces = 0;      ///< sets of triangles joined through shared points
  int degenerate = 0;  ///< triangles naming a point twice
};

/// `triangles` over points 0 .. point_count - 1 (every id must be below point_count).
inline SurfaceCheck check_surface(const std::vector<std::array<int, 3>>& triangles, int point_count) {
  SurfaceCheck check;
  std::map<std::pair<int, int>, int> directed;  // (from, to) -> triangles
  std::vector<int> parent(static_cast<std::size_t>(point_count));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int v) {
    while (parent[static_cast<std::size_t>(v)] != v) {
      v = parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    }
    return v;
  };
  for (const auto& t : triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) ++check.degenerate;
    for (std::size_t c = 0; c < 3; ++c) {
      ++directed[{t[c], t[(c + 1) % 3]}];
      parent[static_cast<std::size_t>(root(t[c]))] = root(t[(c + 1) % 3]);
    }
  }
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    if (count != 1 || back == directed.end() || back->second != 1) ++check.open_edges;
  }
  std::set<int> roots;
  for (const auto& t : triangles) roots.insert(root(t[0]));
  check.pieces = static_cast<int>(roots.size());
  return check;
}

}  // namespace tissue::test_support
