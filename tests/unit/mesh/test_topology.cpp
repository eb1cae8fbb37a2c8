// Surface and adjacency: the surface is closed, outward and encloses the mesh volume; the
// box meshes are conforming; face, edge and vertex adjacency agree with each other and with
// Euler's formula for a ball (V - E + F - T = 1).
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "reference_meshes.hpp"

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <utility>

namespace tissue {
namespace {

const std::filesystem::path MESH_DIR = TISSUE_MESH_DIR;

const Eigen::Vector3d& position(const TetMesh& mesh, int v) {
  return mesh.rest_positions_m[static_cast<std::size_t>(v)];
}

double tet_volume(const TetMesh& mesh, const Tet& tet) {
  return signed_tet_volume(position(mesh, tet[0]), position(mesh, tet[1]), position(mesh, tet[2]),
                           position(mesh, tet[3]));
}

/// Outward (unnormalised, |n| = 2 * area) normal of a surface triangle.
Eigen::Vector3d triangle_normal(const TetMesh& mesh, const std::array<int, 3>& tri) {
  return (position(mesh, tri[1]) - position(mesh, tri[0])).cross(position(mesh, tri[2]) - position(mesh, tri[0]));
}

/// Orders the vertices of each tet for positive volume (used for hand-written meshes).
void orient(TetMesh& mesh) {
  for (Tet& tet : mesh.tets) {
    if (tet_volume(mesh, tet) < 0.0) {
      std::swap(tet[2], tet[3]);
    }
  }
}

/// The unit cube as 6 tets around the diagonal 0-7 (corner c at (c & 1, c >> 1 & 1, c >> 2 & 1)).
TetMesh six_tet_cube() {
  TetMesh mesh;
  for (int c = 0; c < 8; ++c) {
    mesh.rest_positions_m.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  }
  mesh.tets = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  orient(mesh);
  return mesh;
}

double total_volume(const TetMesh& mesh) {
  double volume_m3 = 0.0;
  for (const Tet& tet : mesh.tets) {
    volume_m3 += tet_volume(mesh, tet);
  }
  return volume_m3;
}

/// Closed and consistently oriented: every directed edge of the surface appears exactly once
/// and its reverse exactly once (so every undirected edge is shared by exactly two triangles).
void expect_closed_and_oriented(const SurfaceMesh& surface) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& tri : surface.triangles) {
    for (int k = 0; k < 3; ++k) {
      ++directed[{tri[static_cast<std::size_t>(k)], tri[static_cast<std::size_t>((k + 1) % 3)]}];
    }
  }
  for (const auto& [edge, count] : directed) {
    ASSERT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second << " used twice in the same direction";
    const auto reverse = directed.find({edge.second, edge.first});
    ASSERT_NE(reverse, directed.end()) << "edge " << edge.first << "-" << edge.second << " is on one triangle only";
  }
}

/// Divergence theorem: the volume enclosed by an outward surface is sum a . (b x c) / 6.
double enclosed_volume(const TetMesh& mesh, const SurfaceMesh& surface) {
  double volume_m3 = 0.0;
  for (const auto& tri : surface.triangles) {
    volume_m3 += position(mesh, tri[0]).dot(position(mesh, tri[1]).cross(position(mesh, tri[2]))) / 6.0;
  }
  return volume_m3;
}

double surface_area(const TetMesh& mesh, const SurfaceMesh& surface) {
  double area_m2 = 0.0;
  for (const auto& tri : surface.triangles) {
    area_m2 += 0.5 * triangle_normal(mesh, tri).norm();
  }
  return area_m2;
}

void expect_watertight_surface(const TetMesh& mesh) {
  const SurfaceMesh surface = extract_surface(mesh);
  ASSERT_FALSE(surface.triangles.empty());
  expect_closed_and_oriented(surface);
  const double volume_m3 = total_volume(mesh);
  EXPECT_NEAR(enclosed_volume(mesh, surface), volume_m3, 1e-12 * volume_m3);
  // Each triangle is the stated face of the stated tet.
  for (std::size_t s = 0; s < surface.triangles.size(); ++s) {
    const Tet& tet = mesh.tets[static_cast<std::size_t>(surface.triangle_tet[s])];
    const auto& local = TET_FACES[static_cast<std::size_t>(surface.triangle_local_face[s])];
    for (std::size_t k = 0; k < 3; ++k) {
      ASSERT_EQ(surface.triangles[s][k], tet[static_cast<std::size_t>(local[k])]);
    }
  }
  std::set<int> vertices;
  for (const auto& tri : surface.triangles) {
    vertices.insert(tri.begin(), tri.end());
  }
  EXPECT_EQ(surface.vertices, std::vector<int>(vertices.begin(), vertices.end()));
}

/// Checks the adjacency against brute force and returns V - E + F - T.
int check_adjacency(const TetMesh& mesh) {
  const TetAdjacency adjacency = build_adjacency(mesh);
  const int tet_count = mesh.tet_count();
  EXPECT_EQ(static_cast<int>(adjacency.face_neighbor.size()), tet_count);
  EXPECT_EQ(static_cast<int>(adjacency.tet_edges.size()), tet_count);

  // Faces: a neighbour shares exactly the three vertices of the face, and names us back.
  int boundary_faces = 0;
  int interior_face_sides = 0;
  for (int t = 0; t < tet_count; ++t) {
    const Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    for (int k = 0; k < 4; ++k) {
      const int other = adjacency.face_neighbor[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)];
      if (other < 0) {
        ++boundary_faces;
        continue;
      }
      ++interior_face_sides;
      EXPECT_NE(other, t);
      const Tet& neighbour = mesh.tets[static_cast<std::size_t>(other)];
      std::set<int> face;
      for (const int local : TET_FACES[static_cast<std::size_t>(k)]) {
        face.insert(tet[static_cast<std::size_t>(local)]);
      }
      int shared = 0;
      for (const int v : neighbour) {
        shared += static_cast<int>(face.count(v));
      }
      EXPECT_EQ(shared, 3) << "tets " << t << " and " << other;
      const auto& back = adjacency.face_neighbor[static_cast<std::size_t>(other)];
      EXPECT_EQ(std::count(back.begin(), back.end(), t), 1) << "face_neighbor not symmetric for " << t << ", " << other;
    }
  }
  // Interior faces have two sides, boundary faces one, and nothing else exists.
  std::map<std::array<int, 3>, int> face_count;
  for (const Tet& tet : mesh.tets) {
    for (const auto& local : TET_FACES) {
      std::array<int, 3> key = {tet[static_cast<std::size_t>(local[0])], tet[static_cast<std::size_t>(local[1])],
                                tet[static_cast<std::size_t>(local[2])]};
      std::sort(key.begin(), key.end());
      ++face_count[key];
    }
  }
  for (const auto& [face, count] : face_count) {
    EXPECT_LE(count, 2);
  }
  const int face_total = static_cast<int>(face_count.size());
  EXPECT_EQ(face_total, boundary_faces + interior_face_sides / 2);
  EXPECT_EQ(boundary_faces, static_cast<int>(extract_surface(mesh).triangles.size()));

  // Edges: unique, sorted endpoints, consistent with tet_edges and edge_tets.
  const auto edge_count = adjacency.edges.size();
  EXPECT_EQ(adjacency.edge_tets_begin.size(), edge_count + 1);
  EXPECT_EQ(static_cast<int>(adjacency.edge_tets.size()), 6 * tet_count);
  std::set<std::array<int, 2>> unique_edges(adjacency.edges.begin(), adjacency.edges.end());
  EXPECT_EQ(unique_edges.size(), edge_count);
  for (const auto& edge : adjacency.edges) {
    EXPECT_LT(edge[0], edge[1]);
  }
  for (int t = 0; t < tet_count; ++t) {
    const Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    for (std::size_t k = 0; k < 6; ++k) {
      const int e = adjacency.tet_edges[static_cast<std::size_t>(t)][k];
      const int a = tet[static_cast<std::size_t>(TET_EDGES[k][0])];
      const int b = tet[static_cast<std::size_t>(TET_EDGES[k][1])];
      EXPECT_EQ(adjacency.edges[static_cast<std::size_t>(e)], (std::array<int, 2>{std::min(a, b), std::max(a, b)}));
      const auto begin = adjacency.edge_tets.begin() + adjacency.edge_tets_begin[static_cast<std::size_t>(e)];
      const auto end = adjacency.edge_tets.begin() + adjacency.edge_tets_begin[static_cast<std::size_t>(e) + 1];
      EXPECT_EQ(std::count(begin, end, t), 1) << "tet " << t << " missing around its edge " << e;
    }
  }
  // Every tet listed around an edge really contains it.
  for (std::size_t e = 0; e < edge_count; ++e) {
    for (int n = adjacency.edge_tets_begin[e]; n < adjacency.edge_tets_begin[e + 1]; ++n) {
      const auto& ids = adjacency.tet_edges[static_cast<std::size_t>(adjacency.edge_tets[static_cast<std::size_t>(n)])];
      EXPECT_EQ(std::count(ids.begin(), ids.end(), static_cast<int>(e)), 1);
    }
  }

  // Vertices: tets around each vertex contain it; 4 entries per tet.
  EXPECT_EQ(static_cast<int>(adjacency.vertex_tets_begin.size()), mesh.vertex_count() + 1);
  EXPECT_EQ(static_cast<int>(adjacency.vertex_tets.size()), 4 * tet_count);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    for (int n = adjacency.vertex_tets_begin[static_cast<std::size_t>(v)];
         n < adjacency.vertex_tets_begin[static_cast<std::size_t>(v) + 1]; ++n) {
      const Tet& tet = mesh.tets[static_cast<std::size_t>(adjacency.vertex_tets[static_cast<std::size_t>(n)])];
      EXPECT_NE(std::find(tet.begin(), tet.end(), v), tet.end());
    }
  }
  return mesh.vertex_count() - static_cast<int>(edge_count) + face_total - tet_count;
}

TEST(TetFaces, AreOutwardForPositiveTets) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    TetMesh mesh;
    for (int v = 0; v < 4; ++v) {
      mesh.rest_positions_m.emplace_back(coordinate(random), coordinate(random), coordinate(random));
    }
    mesh.tets = {{0, 1, 2, 3}};
    orient(mesh);
    const Tet& tet = mesh.tets[0];
    for (std::size_t k = 0; k < 4; ++k) {
      const auto& local = TET_FACES[k];
      const std::array<int, 3> tri = {tet[static_cast<std::size_t>(local[0])], tet[static_cast<std::size_t>(local[1])],
                                      tet[static_cast<std::size_t>(local[2])]};
      // Face k is opposite vertex k, and its normal points away from it.
      EXPECT_EQ(std::count(tri.begin(), tri.end(), tet[k]), 0);
      EXPECT_LT(triangle_normal(mesh, tri).dot(position(mesh, tet[k]) - position(mesh, tri[0])), 0.0);
    }
  }
}

TEST(ExtractSurface, SingleTetGivesFourOutwardTriangles) {
  TetMesh mesh;
  mesh.rest_positions_m = {{0.1, 0.0, 0.0}, {1.0, 0.2, 0.0}, {0.0, 1.0, 0.3}, {0.2, 0.1, 1.0}};
  mesh.tets = {{0, 1, 2, 3}};
  ASSERT_GT(tet_volume(mesh, mesh.tets[0]), 0.0);
  const SurfaceMesh surface = extract_surface(mesh);
  ASSERT_EQ(surface.triangles.size(), 4U);
  const Eigen::Vector3d centroid = (position(mesh, 0) + position(mesh, 1) + position(mesh, 2) + position(mesh, 3)) / 4;
  for (std::size_t s = 0; s < 4; ++s) {
    const auto& tri = surface.triangles[s];
    const Eigen::Vector3d face_centroid =
        (position(mesh, tri[0]) + position(mesh, tri[1]) + position(mesh, tri[2])) / 3;
    EXPECT_GT(triangle_normal(mesh, tri).dot(face_centroid - centroid), 0.0) << "triangle " << s;
    EXPECT_EQ(surface.triangle_tet[s], 0);
    EXPECT_EQ(surface.triangle_local_face[s], static_cast<int>(s));
  }
  EXPECT_EQ(surface.vertices, (std::vector<int>{0, 1, 2, 3}));
  expect_watertight_surface(mesh);
}

TEST(ExtractSurface, FiveTetCubeIsClosedAndEnclosesItsVolume) {
  const TetMesh cube = make_box_mesh(1, 1, 1, 1.0);
  ASSERT_EQ(cube.tet_count(), 5);
  const SurfaceMesh surface = extract_surface(cube);
  EXPECT_EQ(surface.triangles.size(), 12U);  // two per cube face
  EXPECT_EQ(surface.vertices.size(), 8U);
  EXPECT_NEAR(total_volume(cube), 1.0, 1e-15);
  expect_watertight_surface(cube);
  EXPECT_NEAR(surface_area(cube, surface), 6.0, 1e-12);
}

TEST(ExtractSurface, SixTetCubeIsClosedAndEnclosesItsVolume) {
  const TetMesh cube = six_tet_cube();
  EXPECT_NEAR(total_volume(cube), 1.0, 1e-15);
  const SurfaceMesh surface = extract_surface(cube);
  EXPECT_EQ(surface.triangles.size(), 12U);
  expect_watertight_surface(cube);
}

TEST(ExtractSurface, BoxMeshesAreConforming) {
  // A non-conforming split (mismatched face diagonals) leaves interior faces unshared, which
  // adds their area to the surface; a conforming box has exactly its outer area.
  for (const auto& [nx, ny, nz] : {std::array<int, 3>{2, 1, 1}, {3, 2, 2}, {4, 3, 5}}) {
    const double edge_m = 0.01;
    const TetMesh box = make_box_mesh(nx, ny, nz, edge_m);
    SCOPED_TRACE(::testing::Message() << nx << "x" << ny << "x" << nz);
    const SurfaceMesh surface = extract_surface(box);
    const double lx = nx * edge_m;
    const double ly = ny * edge_m;
    const double lz = nz * edge_m;
    EXPECT_NEAR(surface_area(box, surface), 2 * (lx * ly + ly * lz + lx * lz), 1e-15);
    EXPECT_EQ(surface.triangles.size(), static_cast<std::size_t>(4 * (nx * ny + ny * nz + nx * nz)));
    expect_watertight_surface(box);
    EXPECT_NEAR(total_volume(box), lx * ly * lz, 1e-18);
  }
}

TEST(ExtractSurface, BarFileIsConformingWithTheOuterArea) {
  const TetMesh bar = read_mesh(MESH_DIR / "bar_40x8x8.veg");
  const SurfaceMesh surface = extract_surface(bar);
  EXPECT_NEAR(surface_area(bar, surface), 2 * (0.4 * 0.08 * 2 + 0.08 * 0.08), 1e-12);
  expect_watertight_surface(bar);
}

TEST(ExtractSurface, FrogIsOneClosedSurface) {
  const TetMesh frog = read_mesh(MESH_DIR / "frog.msh");
  const SurfaceMesh surface = extract_surface(frog);
  expect_watertight_surface(frog);
  // A closed genus-0 surface: V - E + F = 2.
  std::set<std::pair<int, int>> edges;
  for (const auto& tri : surface.triangles) {
    for (std::size_t k = 0; k < 3; ++k) {
      const int a = tri[k];
      const int b = tri[(k + 1) % 3];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  EXPECT_EQ(static_cast<int>(surface.vertices.size()) - static_cast<int>(edges.size()) +
                static_cast<int>(surface.triangles.size()),
            2);
}

TEST(ExtractSurface, VegaReferenceSurfacesAreClosed) {
  TISSUE_SKIP_WITHOUT_VEGA_MESHES();
  const std::filesystem::path vega_dir = test_data::vega_reference_dir();
  for (const char* file : {"simpleBridge/simpleBridge-ic_128_0.15_.1.veg", "turtle/turtle-volumetric-homogeneous.veg",
                           "comb/comb.tet.veg", "beam3/beam3_tet.veg"}) {
    SCOPED_TRACE(file);
    expect_watertight_surface(read_mesh(vega_dir / file));
  }
}

TEST(ExtractSurface, RefusesFaceSharedByThreeTets) {
  TetMesh mesh;
  mesh.rest_positions_m = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.2, 0.2, 1}, {0.3, 0.1, -1}};
  mesh.tets = {{0, 1, 2, 3}, {0, 1, 2, 4}, {0, 1, 2, 5}};
  orient(mesh);
  EXPECT_THROW(extract_surface(mesh), MeshError);
  EXPECT_THROW(build_adjacency(mesh), MeshError);
}

TEST(BuildAdjacency, SingleTetHasNoNeighbours) {
  TetMesh mesh;
  mesh.rest_positions_m = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.tets = {{0, 1, 2, 3}};
  const TetAdjacency adjacency = build_adjacency(mesh);
  EXPECT_EQ(adjacency.face_neighbor[0], (std::array<int, 4>{-1, -1, -1, -1}));
  EXPECT_EQ(adjacency.edges.size(), 6U);
  EXPECT_EQ(check_adjacency(mesh), 1);
}

TEST(BuildAdjacency, CubesAreBallsByEuler) {
  EXPECT_EQ(check_adjacency(make_box_mesh(1, 1, 1, 1.0)), 1);
  EXPECT_EQ(check_adjacency(six_tet_cube()), 1);
  // The 5-tet cube: the central tet (0) touches the four corner tets, which touch nothing else.
  const TetAdjacency adjacency = build_adjacency(make_box_mesh(1, 1, 1, 1.0));
  std::array<int, 4> around_central = adjacency.face_neighbor[0];
  std::sort(around_central.begin(), around_central.end());
  EXPECT_EQ(around_central, (std::array<int, 4>{1, 2, 3, 4}));
  for (std::size_t t = 1; t < 5; ++t) {
    EXPECT_EQ(std::count(adjacency.face_neighbor[t].begin(), adjacency.face_neighbor[t].end(), -1), 3);
  }
}

TEST(BuildAdjacency, BeamAndBarAreBallsByEuler) {
  EXPECT_EQ(check_adjacency(read_mesh(MESH_DIR / "beam_10x2x2.veg")), 1);
  EXPECT_EQ(check_adjacency(make_box_mesh(4, 3, 2, 0.01)), 1);
  EXPECT_EQ(check_adjacency(read_mesh(MESH_DIR / "bar_40x8x8.veg")), 1);
}

TEST(BuildAdjacency, FrogIsABallByEuler) { EXPECT_EQ(check_adjacency(read_mesh(MESH_DIR / "frog.msh")), 1); }

// Mean |rank(a) - rank(b)| over the mesh's edges, ranks by `order` (order[k] = vertex).
double mean_edge_span(const TetAdjacency& adjacency, const std::vector<int>& order) {
  std::vector<int> rank(order.size());
  for (size_t k = 0; k < order.size(); ++k) rank[static_cast<size_t>(order[k])] = static_cast<int>(k);
  double sum = 0.0;
  for (const auto& edge : adjacency.edges) sum += std::abs(rank[static_cast<size_t>(edge[0])] - rank[static_cast<size_t>(edge[1])]);
  return sum / static_cast<double>(adjacency.edges.size());
}

bool is_permutation_of(const std::vector<int>& order, int n) {
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < n; ++k) {
    if (sorted.size() != static_cast<size_t>(n) || sorted[static_cast<size_t>(k)] != k) return false;
  }
  return true;
}

TEST(LocalityOrder, BringsTheNeighboursOfAShuffledMeshClose) {
  const TetMesh box = make_box_mesh(12, 6, 6, 0.01);
  // The same mesh with its vertices numbered at random, as a Delaunay mesher's insertion order.
  std::vector<int> shuffle(static_cast<size_t>(box.vertex_count()));
  std::iota(shuffle.begin(), shuffle.end(), 0);
  std::mt19937 rng(23);
  std::shuffle(shuffle.begin(), shuffle.end(), rng);
  TetMesh shuffled = box;
  for (size_t v = 0; v < shuffle.size(); ++v) shuffled.rest_positions_m[static_cast<size_t>(shuffle[v])] = box.rest_positions_m[v];
  for (Tet& tet : shuffled.tets) {
    for (int& v : tet) v = shuffle[static_cast<size_t>(v)];
  }
  const TetAdjacency adjacency = build_adjacency(shuffled);
  const std::vector<int> order = locality_order(adjacency, shuffled.vertex_count());
  ASSERT_TRUE(is_permutation_of(order, shuffled.vertex_count()));
  std::vector<int> own(order.size());
  std::iota(own.begin(), own.end(), 0);
  const double before = mean_edge_span(adjacency, own);
  const double after = mean_edge_span(adjacency, order);
  std::printf("shuffled 12x6x6 box: mean edge span %.1f -> %.1f\n", before, after);
  // Random ranks are n/3 apart on average (~340 here); a level-by-level order keeps an edge within
  // about one cross-section of 7 x 7 vertices.
  EXPECT_LT(after, 0.2 * before);
  EXPECT_LT(after, 7.0 * 7.0);
}

TEST(LocalityOrder, KeepsAnOrderThatIsLocalAlready) {
  const TetMesh box = make_box_mesh(12, 6, 6, 0.01);  // x fastest: neighbours are close already
  const std::vector<int> order = locality_order(build_adjacency(box), box.vertex_count());
  std::vector<int> own(order.size());
  std::iota(own.begin(), own.end(), 0);
  EXPECT_EQ(order, own);
}

TEST(OrderRanks, InvertAPermutationAndRefuseAnythingElse) {
  EXPECT_EQ(order_ranks({2, 0, 1}, 3, "test"), (std::vector<int>{1, 2, 0}));
  EXPECT_THROW((void)order_ranks({2, 0, 2}, 3, "test"), std::invalid_argument);  // a vertex twice
  EXPECT_THROW((void)order_ranks({0, 1}, 3, "test"), std::invalid_argument);     // one missing
  EXPECT_THROW((void)order_ranks({0, 1, 3}, 3, "test"), std::invalid_argument);  // out of range
}

TEST(LocalityOrder, ListsEveryVertexOfSeveralPiecesAndUnusedOnes) {
  TetMesh mesh = make_box_mesh(2, 1, 1, 0.01);
  const int first_piece = mesh.vertex_count();
  const TetMesh second = make_box_mesh(1, 1, 1, 0.01);
  for (const Eigen::Vector3d& p : second.rest_positions_m) mesh.rest_positions_m.push_back(p + Eigen::Vector3d(1, 0, 0));
  for (Tet tet : second.tets) {
    for (int& v : tet) v += first_piece;
    mesh.tets.push_back(tet);
  }
  mesh.rest_positions_m.push_back(Eigen::Vector3d(5, 5, 5));  // on no tet
  const std::vector<int> order = locality_order(build_adjacency(mesh), mesh.vertex_count());
  ASSERT_TRUE(is_permutation_of(order, mesh.vertex_count()));
  EXPECT_EQ(order.back(), mesh.vertex_count() - 1);
}

}  // namespace
}  // namespace tissue
