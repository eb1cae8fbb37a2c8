// Door: a Gmsh .msh 4.1 file (read_gmsh -> parse_gmsh). Promise: refused with a MeshError, or
// accepted and steppable.
#include "core/mesh/mesh_io.hpp"
#include "support/accepted_mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return tissue::fuzz::mesh_door([&] { return tissue::parse_gmsh(tissue::fuzz::as_text(data, size), "fuzz.msh"); },
                                 "gmsh");
}
