// The 5-tet box generator; meshes/make_bar.py holds the same tables and must stay in step
// (test_mesh_io compares meshes/bar_40x8x8.veg against make_box_mesh(40, 8, 8, 0.01)).
#include "core/mesh/box_mesh.hpp"

#include <cmath>
#include <stdexcept>

namespace tissue {
namespace {

/// Cube corners are numbered c = x + 2y + 4z with x, y, z in {0, 1}. For a cube with i+j+k even
/// the central tet joins the even corners (0, 3, 5, 6) and each odd corner cuts off a corner tet
/// with its three neighbours; for odd i+j+k the roles swap. The four face diagonals of the
/// central tet are then the ones a neighbour (of the other parity) uses too. Each row is
/// already ordered for positive volume.
constexpr int SPLIT[2][5][4] = {
    {{0, 3, 6, 5}, {1, 0, 5, 3}, {2, 3, 6, 0}, {4, 5, 0, 6}, {7, 6, 3, 5}},
    {{1, 2, 4, 7}, {0, 1, 2, 4}, {3, 2, 1, 7}, {5, 4, 7, 1}, {6, 7, 4, 2}},
};

}  // namespace

TetMesh make_box_mesh(int nx, int ny, int nz, double cube_edge_m) {
  if (nx < 1 || ny < 1 || nz < 1 || !(cube_edge_m > 0.0) || !std::isfinite(cube_edge_m)) {
    throw std::invalid_argument("make_box_mesh: need nx, ny, nz >= 1 and a finite cube_edge_m > 0");
  }
  const auto vertex_id = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };

  TetMesh mesh;
  mesh.rest_positions_m.reserve(static_cast<std::size_t>(nx + 1) * static_cast<std::size_t>(ny + 1) *
                                static_cast<std::size_t>(nz + 1));
  for (int k = 0; k <= nz; ++k) {
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        mesh.rest_positions_m.emplace_back(i * cube_edge_m, j * cube_edge_m, k * cube_edge_m);
      }
    }
  }
  mesh.tets.reserve(5 * static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz));
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const int parity = (i + j + k) % 2;
        for (const auto& local : SPLIT[parity]) {
          Tet tet{};
          for (std::size_t n = 0; n < 4; ++n) {
            const int c = local[n];
            tet[n] = vertex_id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
          }
          mesh.tets.push_back(tet);
        }
      }
    }
  }
  return mesh;
}

}  // namespace tissue
