// A mesh a reader accepted must be usable: the core builds a tissue on it and steps it 10 times
// with a finite state (fuzz/README.md).
#pragma once

#include "core/mesh/tet_mesh.hpp"
#include "support/promise.hpp"

namespace tissue::fuzz {

/// Aborts (a broken promise) unless `mesh` steps 10 times with finite positions, or is refused by
/// the tissue with a ParameterError naming why.
void require_steps(const TetMesh& mesh);

/// A mesh reader's door: `parse()` refuses with a MeshError that says why, or its mesh steps.
template <class Parse>
int mesh_door(Parse&& parse, const char* door) {
  TetMesh mesh;
  try {
    mesh = parse();
  } catch (const MeshError& error) {
    require_message(error.what(), door);
    return 0;
  }
  require_steps(mesh);
  return 0;
}

}  // namespace tissue::fuzz
