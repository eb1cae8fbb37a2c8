// Surface extraction and adjacency of a tet mesh: boundary triangles (outward-oriented),
// face -> neighbour tet and edge -> tets, as the volume cutter (issue 3) walks them.
#pragma once

#include "core/mesh/tet_mesh.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace tissue {

/// Local faces of a tet: face k is opposite vertex k, wound so that its normal points outward
/// for a positively oriented tet.
inline constexpr std::array<std::array<int, 3>, 4> TET_FACES = {{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};
/// Local edges of a tet (pairs of local vertex indices).
inline constexpr std::array<std::array<int, 2>, 6> TET_EDGES = {{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
/// The index into TET_EDGES of the local edge between vertices a and b, in either order; -1 if a == b.
inline constexpr int local_edge(int a, int b) {
  for (int k = 0; k < 6; ++k) {
    const auto& edge = TET_EDGES[static_cast<std::size_t>(k)];
    if ((edge[0] == a && edge[1] == b) || (edge[0] == b && edge[1] == a)) return k;
  }
  return -1;
}

/// The longest edge of the tet with these corners. [m]
inline double largest_edge_m(const std::array<Eigen::Vector3d, 4>& corners) {
  double longest = 0.0;
  for (const auto& edge : TET_EDGES) {
    const auto [a, b] = edge;
    longest = std::max(longest, (corners[static_cast<std::size_t>(a)] - corners[static_cast<std::size_t>(b)]).norm());
  }
  return longest;
}

struct SurfaceMesh {
  std::vector<std::array<int, 3>> triangles;  ///< mesh vertex ids, outward normal (right-hand rule)
  std::vector<int> triangle_tet;              ///< the tet each triangle belongs to
  std::vector<int> triangle_local_face;       ///< which local face (0..3) of that tet
  std::vector<int> vertices;                  ///< sorted ids of vertices on the surface
};

/// Boundary faces: those that belong to exactly one tet, in tet order (then local-face order).
/// Throws MeshError (no file, line 0) if a face is shared by more than two tets (overlapping elements).
SurfaceMesh extract_surface(const TetMesh& mesh);

/// Throws MeshError (naming the third tet) if a face is shared by more than two tets.
void check_face_sharing(const TetMesh& mesh);

struct TetAdjacency {
  /// face_neighbor[t][k]: the tet across local face k of tet t, or -1 on the boundary.
  std::vector<std::array<int, 4>> face_neighbor;
  /// Unique edges (v0 < v1).
  std::vector<std::array<int, 2>> edges;
  /// tet_edges[t][k]: id of local edge k (TET_EDGES) of tet t.
  std::vector<std::array<int, 6>> tet_edges;
  /// CSR: the tets around edge e are edge_tets[edge_tets_begin[e] .. edge_tets_begin[e+1]).
  std::vector<int> edge_tets_begin;
  std::vector<int> edge_tets;
  /// CSR: the tets around vertex v.
  std::vector<int> vertex_tets_begin;
  std::vector<int> vertex_tets;
};

/// Edges are numbered in lexicographic (v0, v1) order; the tets around an edge or a vertex are listed
/// in increasing order. Throws MeshError like extract_surface for a face shared by more than two tets.
TetAdjacency build_adjacency(const TetMesh& mesh);

/// The vertices in an order that keeps neighbours close (reverse Cuthill-McKee over the edge graph:
/// each connected part from a pseudo-peripheral vertex, neighbours by increasing degree, ties by
/// id), as order[k] = vertex. Numbering a system's block rows and visiting its tets in this order
/// keeps the blocks a tet writes, and the entries a mat-vec reads, close in memory: a mesh from a
/// Delaunay mesher comes numbered in insertion order, and its assembly then misses the cache on
/// nearly every block (docs/BENCHMARKS.md, issue 23). Deterministic; vertices on no edge go last.
/// A mesh whose own numbering is about as local (its mean edge span at most twice the reordering's)
/// keeps it: the identity order, which also keeps vertex-indexed arrays in step with the rows.
std::vector<int> locality_order(const TetAdjacency& adjacency, int vertex_count);

/// rank[v] = k where order[k] = v: the position of each vertex in a vertex order. Throws
/// std::invalid_argument (prefixed by `who`) unless `order` is a permutation of [0, vertex_count).
std::vector<int> order_ranks(const std::vector<int>& order, int vertex_count, const char* who);

}  // namespace tissue
