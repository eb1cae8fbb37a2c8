// The material parts of a cut body, for tests: the simulation's own connectivity.
#pragma once

#include "core/fem/deformable_body.hpp"

#include <algorithm>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

namespace tissue {

/// The body's material parts (cells joined where they share a copy of a vertex, real or ghost: the
/// simulation's own connectivity) and their rest volumes, largest first. [m^3]
inline std::vector<double> material_part_volumes_m3(const TetMesh& mesh, const DeformableBody& body) {
  const int vertices = mesh.vertex_count();
  const int rows = body.dof_count() / 3;
  std::vector<int> parent(static_cast<size_t>(vertices + rows) + body.held_copies().size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](int i) {
    while (parent[static_cast<size_t>(i)] != i) i = parent[static_cast<size_t>(i)] = parent[static_cast<size_t>(parent[static_cast<size_t>(i)])];
    return i;
  };
  std::vector<std::pair<int, double>> cells;  // (a copy of the cell, volume)
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets[static_cast<size_t>(t)];
    const int k = body.cut_tet_index(t);
    if (k < 0) {
      for (size_t j = 1; j < 4; ++j) parent[static_cast<size_t>(find(tet[j]))] = find(tet[0]);
      const auto x = mesh.rest_corners(t);
      cells.emplace_back(tet[0], signed_tet_volume(x[0], x[1], x[2], x[3]));
      continue;
    }
    for (int p = 0; p < static_cast<int>(body.xfem().piece_count(k)); ++p) {
      const CutPiece& piece = body.xfem().piece(k, p);
      const auto copy = [&](size_t j) {  // the real vertex, a ghost row, or a held copy (issue 41)
        const int row = piece.ghost_row[j];
        return row == -1 ? tet[j] : vertices + (row >= 0 ? row : rows + held_copy_index(row));
      };
      for (size_t j = 1; j < 4; ++j) parent[static_cast<size_t>(find(copy(j)))] = find(copy(0));
      cells.emplace_back(copy(0), body.piece_mass_kg(k, p) / body.settings().material.density_kg_per_m3);
    }
  }
  std::map<int, double> volume;
  for (const auto& [copy, v] : cells) volume[find(copy)] += v;
  std::vector<double> volumes;
  for (const auto& [root, v] : volume) volumes.push_back(v);
  std::sort(volumes.rbegin(), volumes.rend());
  return volumes;
}

}  // namespace tissue
