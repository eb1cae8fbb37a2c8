// Surface extraction and adjacency by sorting: every tet face (edge) gets a key made of its
// sorted vertex ids; after one O(n log n) sort, the copies of a face (edge) are neighbours.
// Sorting rather than hashing also makes the output order independent of the hash function.
#include "core/mesh/topology.hpp"

#include <algorithm>
#include <cstdlib>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>

namespace tissue {
namespace {

struct FaceKey {
  std::array<int, 3> vertices;  ///< sorted
  int tet_face;                 ///< 4 * tet + local face
};

struct EdgeKey {
  std::array<int, 2> vertices;  ///< sorted
  int tet_edge;                 ///< 6 * tet + local edge
};

/// All tet faces, sorted so that the copies of a face are adjacent and in tet order.
/// Throws MeshError for a face shared by more than two tets (overlapping elements).
std::vector<FaceKey> sorted_faces(const TetMesh& mesh) {
  std::vector<FaceKey> faces;
  faces.reserve(static_cast<std::size_t>(mesh.tet_count()) * 4);
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    for (int k = 0; k < 4; ++k) {
      const auto& local = TET_FACES[static_cast<std::size_t>(k)];
      std::array<int, 3> key = {tet[static_cast<std::size_t>(local[0])], tet[static_cast<std::size_t>(local[1])],
                                tet[static_cast<std::size_t>(local[2])]};
      std::sort(key.begin(), key.end());
      faces.push_back({key, 4 * t + k});
    }
  }
  std::sort(faces.begin(), faces.end(), [](const FaceKey& a, const FaceKey& b) {
    return std::tie(a.vertices[0], a.vertices[1], a.vertices[2], a.tet_face) <
           std::tie(b.vertices[0], b.vertices[1], b.vertices[2], b.tet_face);
  });
  for (std::size_t k = 2; k < faces.size(); ++k) {
    if (faces[k].vertices == faces[k - 2].vertices) {
      const auto& v = faces[k].vertices;
      const int tet = faces[k].tet_face / 4;
      throw MeshError("face (" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) +
                          ") is shared by more than two tets (0-based tets " +
                          std::to_string(faces[k - 2].tet_face / 4) + ", " + std::to_string(faces[k - 1].tet_face / 4) +
                          ", " + std::to_string(tet) + "): overlapping elements",
                      "", 0, tet);
    }
  }
  return faces;
}

}  // namespace

void check_face_sharing(const TetMesh& mesh) { (void)sorted_faces(mesh); }

SurfaceMesh extract_surface(const TetMesh& mesh) {
  const std::vector<FaceKey> faces = sorted_faces(mesh);
  std::vector<int> boundary;
  for (std::size_t k = 0; k < faces.size();) {
    std::size_t end = k + 1;
    while (end < faces.size() && faces[end].vertices == faces[k].vertices) {
      ++end;
    }
    if (end - k == 1) {
      boundary.push_back(faces[k].tet_face);
    }
    k = end;
  }
  // Output in tet order, so the surface does not depend on the vertex numbering.
  std::sort(boundary.begin(), boundary.end());

  SurfaceMesh surface;
  surface.triangles.reserve(boundary.size());
  surface.triangle_tet.reserve(boundary.size());
  surface.triangle_local_face.reserve(boundary.size());
  for (const int tet_face : boundary) {
    const int t = tet_face / 4;
    const int k = tet_face % 4;
    const Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    const auto& local = TET_FACES[static_cast<std::size_t>(k)];
    surface.triangles.push_back({tet[static_cast<std::size_t>(local[0])], tet[static_cast<std::size_t>(local[1])],
                                 tet[static_cast<std::size_t>(local[2])]});
    surface.triangle_tet.push_back(t);
    surface.triangle_local_face.push_back(k);
    for (const int v : surface.triangles.back()) {
      surface.vertices.push_back(v);
    }
  }
  std::sort(surface.vertices.begin(), surface.vertices.end());
  surface.vertices.erase(std::unique(surface.vertices.begin(), surface.vertices.end()), surface.vertices.end());
  return surface;
}

TetAdjacency build_adjacency(const TetMesh& mesh) {
  const int tet_count = mesh.tet_count();
  const int vertex_count = mesh.vertex_count();
  TetAdjacency adjacency;

  // Face neighbours: after sorting, an interior face is a run of exactly two entries.
  adjacency.face_neighbor.assign(static_cast<std::size_t>(tet_count), {-1, -1, -1, -1});
  const std::vector<FaceKey> faces = sorted_faces(mesh);
  for (std::size_t k = 1; k < faces.size(); ++k) {
    if (faces[k].vertices == faces[k - 1].vertices) {
      const int a = faces[k - 1].tet_face;
      const int b = faces[k].tet_face;
      adjacency.face_neighbor[static_cast<std::size_t>(a / 4)][static_cast<std::size_t>(a % 4)] = b / 4;
      adjacency.face_neighbor[static_cast<std::size_t>(b / 4)][static_cast<std::size_t>(b % 4)] = a / 4;
    }
  }

  // Edges: unique edges are numbered in lexicographic (v0, v1) order; the tets around an edge
  // come out in increasing tet order because the sort breaks ties by tet.
  std::vector<EdgeKey> edge_keys;
  edge_keys.reserve(static_cast<std::size_t>(tet_count) * 6);
  for (int t = 0; t < tet_count; ++t) {
    const Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    for (int k = 0; k < 6; ++k) {
      const auto& local = TET_EDGES[static_cast<std::size_t>(k)];
      const int a = tet[static_cast<std::size_t>(local[0])];
      const int b = tet[static_cast<std::size_t>(local[1])];
      edge_keys.push_back({{std::min(a, b), std::max(a, b)}, 6 * t + k});
    }
  }
  std::sort(edge_keys.begin(), edge_keys.end(), [](const EdgeKey& a, const EdgeKey& b) {
    return std::tie(a.vertices[0], a.vertices[1], a.tet_edge) < std::tie(b.vertices[0], b.vertices[1], b.tet_edge);
  });
  adjacency.tet_edges.assign(static_cast<std::size_t>(tet_count), {});
  adjacency.edge_tets.reserve(edge_keys.size());
  for (std::size_t k = 0; k < edge_keys.size(); ++k) {
    if (k == 0 || edge_keys[k].vertices != edge_keys[k - 1].vertices) {
      adjacency.edge_tets_begin.push_back(static_cast<int>(adjacency.edge_tets.size()));
      adjacency.edges.push_back(edge_keys[k].vertices);
    }
    const int edge = static_cast<int>(adjacency.edges.size()) - 1;
    const int t = edge_keys[k].tet_edge / 6;
    adjacency.tet_edges[static_cast<std::size_t>(t)][static_cast<std::size_t>(edge_keys[k].tet_edge % 6)] = edge;
    adjacency.edge_tets.push_back(t);
  }
  adjacency.edge_tets_begin.push_back(static_cast<int>(adjacency.edge_tets.size()));

  // Vertex -> tets by counting sort (tets in increasing order around each vertex).
  adjacency.vertex_tets_begin.assign(static_cast<std::size_t>(vertex_count) + 1, 0);
  for (const Tet& tet : mesh.tets) {
    for (const int v : tet) {
      ++adjacency.vertex_tets_begin[static_cast<std::size_t>(v) + 1];
    }
  }
  for (std::size_t v = 0; v < static_cast<std::size_t>(vertex_count); ++v) {
    adjacency.vertex_tets_begin[v + 1] += adjacency.vertex_tets_begin[v];
  }
  adjacency.vertex_tets.resize(static_cast<std::size_t>(tet_count) * 4);
  std::vector<int> fill(adjacency.vertex_tets_begin.begin(), adjacency.vertex_tets_begin.end() - 1);
  for (int t = 0; t < tet_count; ++t) {
    for (const int v : mesh.tets[static_cast<std::size_t>(t)]) {
      adjacency.vertex_tets[static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++)] = t;
    }
  }
  return adjacency;
}

namespace {
// The mesh's own numbering is kept when its mean edge span (|i - j| over the edges) is at most
// this many times the reordering's.
constexpr double OWN_ORDER_SPAN_FACTOR = 2.0;
}  // namespace

std::vector<int> locality_order(const TetAdjacency& adjacency, int vertex_count) {
  const auto n = static_cast<size_t>(vertex_count);
  // The edge graph in CSR form.
  std::vector<int> begin(n + 1, 0);
  for (const auto& edge : adjacency.edges) {
    ++begin[static_cast<size_t>(edge[0]) + 1];
    ++begin[static_cast<size_t>(edge[1]) + 1];
  }
  for (size_t v = 0; v < n; ++v) begin[v + 1] += begin[v];
  std::vector<int> neighbours(static_cast<size_t>(begin[n]));
  std::vector<int> fill(begin.begin(), begin.end() - 1);
  for (const auto& edge : adjacency.edges) {
    neighbours[static_cast<size_t>(fill[static_cast<size_t>(edge[0])]++)] = edge[1];
    neighbours[static_cast<size_t>(fill[static_cast<size_t>(edge[1])]++)] = edge[0];
  }
  const auto degree = [&](int v) { return begin[static_cast<size_t>(v) + 1] - begin[static_cast<size_t>(v)]; };
  for (size_t v = 0; v < n; ++v) {  // by increasing degree, ties by id: the order BFS visits them in
    std::sort(neighbours.begin() + begin[v], neighbours.begin() + begin[v + 1],
              [&](int a, int b) { return degree(a) < degree(b) || (degree(a) == degree(b) && a < b); });
  }

  std::vector<int> order;
  order.reserve(n);
  std::vector<int> level(n, -1);
  // Breadth-first from `root` over the unvisited vertices (level -1), appending to `order`;
  // returns the first vertex of least degree on the last level.
  const auto sweep = [&](int root, int mark_base) {
    const size_t first = order.size();
    level[static_cast<size_t>(root)] = mark_base;
    order.push_back(root);
    for (size_t k = first; k < order.size(); ++k) {
      const int v = order[k];
      for (int e = begin[static_cast<size_t>(v)]; e < begin[static_cast<size_t>(v) + 1]; ++e) {
        const int w = neighbours[static_cast<size_t>(e)];
        if (level[static_cast<size_t>(w)] < mark_base) {
          level[static_cast<size_t>(w)] = level[static_cast<size_t>(v)] + 1;
          order.push_back(w);
        }
      }
    }
    int far = order.back();
    for (size_t k = first; k < order.size(); ++k) {
      const int v = order[k];
      if (level[static_cast<size_t>(v)] == level[static_cast<size_t>(far)] && degree(v) < degree(far)) far = v;
    }
    return far;
  };
  // Levels of a trial sweep are offset so that the final sweep sees its vertices as unvisited.
  constexpr int TRIAL_BASE = 0;
  const int final_base = vertex_count + 1;
  for (int start = 0; start < vertex_count; ++start) {
    if (level[static_cast<size_t>(start)] >= 0 || degree(start) == 0) continue;
    // A pseudo-peripheral root: sweep twice from the far end of the last sweep.
    const size_t first = order.size();
    int root = sweep(start, TRIAL_BASE);
    for (size_t k = first; k < order.size(); ++k) level[static_cast<size_t>(order[k])] = -1;
    order.resize(first);
    const int farther = sweep(root, TRIAL_BASE);
    for (size_t k = first; k < order.size(); ++k) level[static_cast<size_t>(order[k])] = -1;
    order.resize(first);
    root = farther;
    sweep(root, final_base);
    std::reverse(order.begin() + static_cast<std::ptrdiff_t>(first), order.end());
  }
  for (int v = 0; v < vertex_count; ++v) {
    if (degree(v) == 0) order.push_back(v);
  }

  // A mesh numbered with locality already (a structured grid, a mesh its maker renumbered) keeps
  // its own order: it also keeps the vertex-indexed arrays (positions, forces) in step with the rows.
  const std::vector<int> rank = order_ranks(order, vertex_count, "locality_order");
  double own_span = 0.0, new_span = 0.0;
  for (const auto& edge : adjacency.edges) {
    own_span += std::abs(edge[0] - edge[1]);
    new_span += std::abs(rank[static_cast<size_t>(edge[0])] - rank[static_cast<size_t>(edge[1])]);
  }
  if (own_span <= OWN_ORDER_SPAN_FACTOR * new_span) std::iota(order.begin(), order.end(), 0);
  return order;
}

std::vector<int> order_ranks(const std::vector<int>& order, int vertex_count, const char* who) {
  if (order.size() != static_cast<size_t>(std::max(vertex_count, 0))) {
    throw std::invalid_argument(std::string(who) + ": the vertex order lists " + std::to_string(order.size()) +
                                " vertices, the mesh has " + std::to_string(vertex_count));
  }
  std::vector<int> rank(order.size(), -1);
  for (size_t k = 0; k < order.size(); ++k) {
    const int v = order[k];
    if (v < 0 || v >= vertex_count || rank[static_cast<size_t>(v)] >= 0) {
      throw std::invalid_argument(std::string(who) + ": the vertex order is not a permutation of the vertices (entry " +
                                  std::to_string(k) + " is " + std::to_string(v) + ")");
    }
    rank[static_cast<size_t>(v)] = static_cast<int>(k);
  }
  return rank;
}

}  // namespace tissue
