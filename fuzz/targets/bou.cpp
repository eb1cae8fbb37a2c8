// Door: a Vega .bou fixed-vertex list (read_bou -> parse_bou) for a mesh of 1000 vertices.
// Promise: refused with a MeshError, or ids sorted, unique and in [0, 1000).
#include "core/mesh/mesh_io.hpp"
#include "support/promise.hpp"

#include <algorithm>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue;
  constexpr int VERTICES = 1000;
  try {
    const std::vector<int> ids = parse_bou(fuzz::as_text(data, size), VERTICES, "fuzz.bou");
    if (!std::is_sorted(ids.begin(), ids.end()) || std::adjacent_find(ids.begin(), ids.end()) != ids.end())
      fuzz::broken("bou ids not sorted and unique");
    if (!ids.empty() && (ids.front() < 0 || ids.back() >= VERTICES)) fuzz::broken("bou id out of range");
  } catch (const MeshError& error) {
    fuzz::require_message(error.what(), "bou");
  }
  return 0;
}
