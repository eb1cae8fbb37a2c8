// Door: a Wavefront OBJ render surface (read_obj -> parse_obj, what a scenario's or the FMU's
// renderSurface loads). Promise: refused with a MeshError naming why, or a closed, consistently
// oriented triangle surface with finite coordinates and every index in range, as parse_obj says.
#include "core/mesh/mesh_io.hpp"
#include "support/promise.hpp"

#include <cmath>
#include <map>
#include <utility>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace tissue;
  TriangleSurface surface;
  try {
    surface = parse_obj(fuzz::as_text(data, size), "fuzz.obj");
  } catch (const MeshError& error) {
    fuzz::require_message(error.what(), "obj");
    return 0;
  }
  if (surface.triangles.empty()) fuzz::broken("an obj accepted with no triangle");
  for (const auto& v : surface.vertices_m) {
    if (!v.allFinite()) fuzz::broken("an obj accepted with a non-finite vertex");
  }
  const auto vertices = static_cast<int>(surface.vertices_m.size());
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : surface.triangles) {
    for (std::size_t c = 0; c < 3; ++c) {
      if (t[c] < 0 || t[c] >= vertices) fuzz::broken("an obj accepted with an index out of range");
      ++directed[{t[c], t[(c + 1) % 3]}];
    }
  }
  for (const auto& [edge, count] : directed) {
    const auto back = directed.find({edge.second, edge.first});
    if (count != 1 || back == directed.end() || back->second != 1)
      fuzz::broken("an obj accepted that is not closed and consistently oriented");
  }
  return 0;
}
