// The root of an element of a union-find held as a parent array (internal to libtissue/core: the
// ghosts' grouping around a vertex, a body's parts, the render surface's material parts and shells).
#pragma once

#include <cstddef>
#include <vector>

namespace tissue {

/// The root of element i, halving its path on the way.
inline int find_root(std::vector<int>& parent_of, int i) {
  while (parent_of[static_cast<std::size_t>(i)] != i)
    i = parent_of[static_cast<std::size_t>(i)] = parent_of[static_cast<std::size_t>(parent_of[static_cast<std::size_t>(i)])];
  return i;
}

}  // namespace tissue
