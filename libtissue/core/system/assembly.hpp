// Assembly maps: from the tets of a mesh to the block rows of the system and to the slots of
// a BlockSparseMatrix, computed once so that per-step assembly is a plain indexed write.
#pragma once

#include "core/mesh/tet_mesh.hpp"
#include "core/system/block_sparse_matrix.hpp"

#include <array>
#include <vector>

namespace tissue {

/// Which block row of the system each vertex occupies; fixed vertices have no row (-1).
struct DofMap {
  std::vector<int> vertex_row;  ///< per vertex: block row, or -1 if fixed
  std::vector<int> row_vertex;  ///< per block row: the vertex
  [[nodiscard]] int free_vertex_count() const { return static_cast<int>(row_vertex.size()); }
};

/// Numbers the vertices not in `fixed_vertices` (sorted or not) consecutively: in `order` (a
/// permutation of the vertices, such as locality_order()), or in vertex order when it is empty.
/// Throws std::invalid_argument if `order` is not a permutation of [0, vertex_count).
DofMap make_dof_map(int vertex_count, const std::vector<int>& fixed_vertices, const std::vector<int>& order = {});

/// Block sparsity of the stiffness on the free vertices: row r holds every free vertex sharing a tet with it.
std::vector<std::vector<int>> stiffness_pattern(const TetMesh& mesh, const DofMap& dofs);

/// slots[t][4*a + b] = slot of block (row of vertex a, row of vertex b) of tet t; -1 when either is fixed.
using TetSlots = std::array<int, 16>;
std::vector<TetSlots> make_tet_slots(const TetMesh& mesh, const DofMap& dofs, const BlockSparseMatrix& matrix);

}  // namespace tissue
