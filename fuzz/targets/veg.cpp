// Door: a Vega .veg file (read_veg -> parse_veg, what tissue-host, the FMUs and Python call).
// Promise: refused with a MeshError naming why, or accepted and steppable (require_steps).
#include "core/mesh/mesh_io.hpp"
#include "support/accepted_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return tissue::fuzz::mesh_door([&] { return tissue::parse_veg(tissue::fuzz::as_text(data, size), "fuzz.veg"); },
                                 "veg");
}
