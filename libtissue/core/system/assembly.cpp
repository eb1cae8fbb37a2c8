// Assembly maps: DOF numbering of the free vertices, the block pattern of the stiffness, and
// the per-tet slot table that lets a step assemble R K_e R^T without any index search.
#include "core/system/assembly.hpp"

#include "core/index_cast.hpp"
#include "core/mesh/topology.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace tissue {

namespace {

// Refuses a tet whose vertices are not vertices of the numbered mesh.
void check_tet(const Tet& tet, int t, int vertex_count) {
  for (const int v : tet) {
    if (v < 0 || v >= vertex_count) {
      throw std::invalid_argument("assembly: tet " + std::to_string(t) + " refers to vertex " + std::to_string(v) +
                                  ", outside [0, " + std::to_string(vertex_count) + ")");
    }
  }
}

void check_dofs_match(const TetMesh& mesh, const DofMap& dofs) {
  if (static_cast<int>(dofs.vertex_row.size()) != mesh.vertex_count()) {
    throw std::invalid_argument("assembly: DOF map numbers " + std::to_string(dofs.vertex_row.size()) +
                                " vertices, the mesh has " + std::to_string(mesh.vertex_count()));
  }
}

}  // namespace

DofMap make_dof_map(int vertex_count, const std::vector<int>& fixed_vertices, const std::vector<int>& order) {
  if (vertex_count < 0) throw std::invalid_argument("make_dof_map: negative vertex count");
  std::vector<char> fixed(to_size(vertex_count), 0);
  for (const int v : fixed_vertices) {
    if (v < 0 || v >= vertex_count) {
      throw std::out_of_range("make_dof_map: fixed vertex " + std::to_string(v) + " outside [0, " +
                              std::to_string(vertex_count) + ")");
    }
    fixed[to_size(v)] = 1;
  }
  DofMap dofs;
  if (!order.empty()) (void)order_ranks(order, vertex_count, "make_dof_map");  // refuses a non-permutation
  dofs.vertex_row.assign(to_size(vertex_count), -1);
  for (int k = 0; k < vertex_count; ++k) {
    const int v = order.empty() ? k : order[to_size(k)];
    if (fixed[to_size(v)] != 0) continue;
    dofs.vertex_row[to_size(v)] = static_cast<int>(dofs.row_vertex.size());
    dofs.row_vertex.push_back(v);
  }
  return dofs;
}

std::vector<std::vector<int>> stiffness_pattern(const TetMesh& mesh, const DofMap& dofs) {
  check_dofs_match(mesh, dofs);
  std::vector<std::vector<int>> pattern(to_size(dofs.free_vertex_count()));
  for (int r = 0; r < dofs.free_vertex_count(); ++r) pattern[to_size(r)].push_back(r);
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets[to_size(t)];
    check_tet(tet, t, mesh.vertex_count());
    for (const int a : tet) {
      const int row = dofs.vertex_row[to_size(a)];
      if (row < 0) continue;
      for (const int b : tet) {
        const int col = dofs.vertex_row[to_size(b)];
        if (col >= 0) pattern[to_size(row)].push_back(col);
      }
    }
  }
  for (std::vector<int>& row : pattern) {
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
  }
  return pattern;
}

std::vector<TetSlots> make_tet_slots(const TetMesh& mesh, const DofMap& dofs, const BlockSparseMatrix& matrix) {
  check_dofs_match(mesh, dofs);
  std::vector<TetSlots> slots(to_size(mesh.tet_count()));
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets[to_size(t)];
    check_tet(tet, t, mesh.vertex_count());
    TetSlots& tet_slots = slots[to_size(t)];
    for (int a = 0; a < 4; ++a) {
      const int row = dofs.vertex_row[to_size(tet[to_size(a)])];
      for (int b = 0; b < 4; ++b) {
        const int col = dofs.vertex_row[to_size(tet[to_size(b)])];
        int slot = -1;
        if (row >= 0 && col >= 0) {
          slot = matrix.find_slot(row, col);
          if (slot < 0) {
            throw std::invalid_argument("make_tet_slots: the matrix has no block (" + std::to_string(row) + ", " +
                                        std::to_string(col) + ") needed by tet " + std::to_string(t));
          }
        }
        tet_slots[to_size(4 * a + b)] = slot;
      }
    }
  }
  return slots;
}

}  // namespace tissue
