// The parts a cut body has fallen into: the block rows that the elements (uncut tets and the pieces
// of live cut tets) join, and whether a fixed vertex holds each part.
#pragma once

#include <cstdint>
#include <vector>

namespace tissue {

class DeformableBody;

struct BodyParts {
  std::vector<int> part_of_row;    ///< per block row: its part, or -1 when no element uses it (an orphaned ghost)
  std::vector<std::uint8_t> held;  ///< per part: 1 when one of its elements has a fixed vertex
  [[nodiscard]] int count() const { return static_cast<int>(held.size()); }
};

/// O(elements): a union-find over the rows of every uncut tet and every piece of a live cut tet.
BodyParts find_body_parts(const DeformableBody& body);

}  // namespace tissue
