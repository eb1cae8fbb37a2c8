// Door: the Tissue FMU's Binary surface outputs as an importer decodes them
// (ports/surface_binary.hpp: surface.mesh, surface.embedding, surface.nodes). The first byte picks
// the output. Promise: refused with a SurfaceBinaryError, or every index in range, every number
// finite, and encoding it again gives the same bytes.
#include "ports/surface_binary.hpp"
#include "support/promise.hpp"

#include <cmath>
#include <span>
#include <vector>

namespace {

template <class Output>
void round_trip(std::span<const std::uint8_t> bytes) {
  Output decoded;
  try {
    tissue::ports::decode(bytes, decoded);
  } catch (const tissue::ports::SurfaceBinaryError& error) {
    tissue::fuzz::require_message(error.what(), "surface binary");
    return;
  }
  std::vector<std::uint8_t> again;
  tissue::ports::encode(decoded, again);
  if (again.size() != bytes.size() || !std::equal(again.begin(), again.end(), bytes.begin()))
    tissue::fuzz::broken("an accepted surface output does not encode to the same bytes");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> bytes(data + 1, size - 1);
  switch (data[0] % 3) {
    case 0: round_trip<tissue::ports::SurfaceMesh>(bytes); break;
    case 1: round_trip<tissue::ports::SurfaceEmbedding>(bytes); break;
    default: round_trip<tissue::ports::SurfaceNodes>(bytes); break;
  }
  return 0;
}
