// A box of nx x ny x nz cubes, each split into 5 tets: the bar and beam meshes of meshes/
// (make_bar.py writes the same mesh), built in code so tests can vary the resolution.
#pragma once

#include "core/mesh/tet_mesh.hpp"

namespace tissue {

/// The box [0, nx*e] x [0, ny*e] x [0, nz*e] with e = cube_edge_m, x along the length.
/// Vertex (i, j, k) (0 <= i <= nx, ...) sits at (i*e, j*e, k*e) and has id
/// i + (nx+1) * (j + (ny+1) * k): x fastest, then y, then z. Cubes are numbered the same way
/// (x fastest) and each gives 5 consecutive tets: first the central tet, then the 4 corner tets.
/// The 5-tet split alternates with the parity of i+j+k so that neighbouring cubes cut their
/// shared face along the same diagonal: the mesh is conforming. All tets are positive.
/// Requires nx, ny, nz >= 1 and cube_edge_m > 0 (std::invalid_argument otherwise).
TetMesh make_box_mesh(int nx, int ny, int nz, double cube_edge_m);

}  // namespace tissue
