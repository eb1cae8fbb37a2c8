#include "core/render/embedded_surface.hpp"

#include "core/collide/geometry.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace tissue {

Eigen::Vector4d barycentric_weights(const std::array<Eigen::Vector3d, 4>& x, const Eigen::Vector3d& p) {
  return *tet_barycentric(p, x[0], x[1], x[2], x[3]);  // mesh tets are never degenerate (validate_tets)
}

namespace {

// Distance from p to the tet (0 inside), given p's barycentric weights in it.
double point_tet_distance(const std::array<Eigen::Vector3d, 4>& x, const Eigen::Vector4d& weights,
                          const Eigen::Vector3d& p) {
  if (weights.minCoeff() >= 0.0) return 0.0;
  double nearest = std::numeric_limits<double>::infinity();
  for (int skip = 0; skip < 4; ++skip) {
    if (weights(skip) >= 0.0) continue;  // p lies beyond the faces opposite its negative weights
    std::array<Eigen::Vector3d, 3> face;
    int n = 0;
    for (int k = 0; k < 4; ++k) {
      if (k != skip) face[static_cast<size_t>(n++)] = x[static_cast<size_t>(k)];
    }
    const Eigen::Vector3d closest = closest_point_on_triangle(p, face[0], face[1], face[2]);
    nearest = std::min(nearest, (p - (closest.x() * face[0] + closest.y() * face[1] + closest.z() * face[2])).norm());
  }
  return nearest;
}

// A uniform grid of the tets' bounding boxes, for finding the tets near a point.
class TetGrid {
 public:
  TetGrid(const TetMesh& mesh, double cell_m) : m_cell_m(cell_m) {
    m_lower = m_upper = mesh.rest_positions_m.front();
    for (const Eigen::Vector3d& p : mesh.rest_positions_m) {
      m_lower = m_lower.cwiseMin(p);
      m_upper = m_upper.cwiseMax(p);
    }
    for (int a = 0; a < 3; ++a) {
      m_cells[static_cast<size_t>(a)] = static_cast<int>(std::floor((m_upper(a) - m_lower(a)) / m_cell_m)) + 1;
    }
    m_tets.resize(static_cast<size_t>(m_cells[0] * m_cells[1] * m_cells[2]));
    for (int t = 0; t < mesh.tet_count(); ++t) {
      const auto x = mesh.rest_corners(t);
      Eigen::Vector3d low = x[0], high = x[0];
      for (const auto& corner : x) {
        low = low.cwiseMin(corner);
        high = high.cwiseMax(corner);
      }
      for (int i = cell_of(low.x(), 0); i <= cell_of(high.x(), 0); ++i)
        for (int j = cell_of(low.y(), 1); j <= cell_of(high.y(), 1); ++j)
          for (int k = cell_of(low.z(), 2); k <= cell_of(high.z(), 2); ++k) m_tets[index(i, j, k)].push_back(t);
    }
  }

  /// The tets whose boxes overlap the cells within `reach_m` of p (each once, ascending).
  void near(const Eigen::Vector3d& p, double reach_m, std::vector<int>& out) const {
    out.clear();
    for (int i = cell_of(p.x() - reach_m, 0); i <= cell_of(p.x() + reach_m, 0); ++i)
      for (int j = cell_of(p.y() - reach_m, 1); j <= cell_of(p.y() + reach_m, 1); ++j)
        for (int k = cell_of(p.z() - reach_m, 2); k <= cell_of(p.z() + reach_m, 2); ++k) {
          const auto& list = m_tets[index(i, j, k)];
          out.insert(out.end(), list.begin(), list.end());
        }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

 private:
  [[nodiscard]] int cell_of(double coordinate, int axis) const {
    const double cell = std::floor((coordinate - m_lower(axis)) / m_cell_m);
    return static_cast<int>(std::clamp(cell, 0.0, static_cast<double>(std::max(0, m_cells[static_cast<size_t>(axis)] - 1))));
  }
  [[nodiscard]] size_t index(int i, int j, int k) const {
    return static_cast<size_t>(i + m_cells[0] * (j + m_cells[1] * k));
  }

  double m_cell_m;
  Eigen::Vector3d m_lower, m_upper;
  std::array<int, 3> m_cells{1, 1, 1};
  std::vector<std::vector<int>> m_tets;
};

double mean_edge_m(const TetMesh& mesh) {
  double sum = 0.0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const auto x = mesh.rest_corners(t);
    for (size_t a = 0; a < 4; ++a)
      for (size_t b = a + 1; b < 4; ++b) sum += (x[a] - x[b]).norm();
  }
  return sum / (6.0 * std::max(1, mesh.tet_count()));
}

}  // namespace

double default_max_outside_m(const TetMesh& mesh) { return 0.25 * mean_edge_m(mesh); }

std::vector<SurfaceEmbedding> embed_surface(const TetMesh& mesh, const TriangleSurface& surface,
                                            double max_outside_m, const std::string& source_name) {
  if (!(max_outside_m >= 0.0)) {
    throw std::invalid_argument("embed_surface: the largest distance outside must be >= 0 m, got " +
                                std::to_string(max_outside_m));
  }
  if (mesh.tet_count() == 0) throw std::invalid_argument("embed_surface: the tet mesh has no tet");
  const double cell_m = mean_edge_m(mesh);
  const TetGrid grid(mesh, cell_m);
  std::vector<SurfaceEmbedding> embedding(surface.vertices_m.size());
  std::vector<int> candidates;
  for (size_t v = 0; v < surface.vertices_m.size(); ++v) {
    const Eigen::Vector3d& p = surface.vertices_m[v];
    // Inside: the tet whose smallest weight is largest; else the nearest within the reach.
    double best_inside = -std::numeric_limits<double>::infinity();
    double nearest_m = std::numeric_limits<double>::infinity();
    SurfaceEmbedding inside, outside;
    grid.near(p, max_outside_m, candidates);
    for (const int t : candidates) {
      const Eigen::Vector4d weights = barycentric_weights(mesh.rest_corners(t), p);
      if (weights.minCoeff() >= 0.0 && weights.minCoeff() > best_inside) {
        best_inside = weights.minCoeff();
        inside = {t, weights};
      }
    }
    for (size_t c = 0; c < candidates.size() && inside.tet < 0; ++c) {
      const auto x = mesh.rest_corners(candidates[c]);
      const Eigen::Vector4d weights = barycentric_weights(x, p);
      const double distance_m = point_tet_distance(x, weights, p);
      if (distance_m < nearest_m) {
        nearest_m = distance_m;
        outside = {candidates[c], weights};
      }
    }
    if (inside.tet >= 0) {
      embedding[v] = inside;
    } else if (nearest_m <= max_outside_m) {
      embedding[v] = outside;
    } else {
      std::ostringstream message;
      message << source_name << ": vertex " << v + 1 << " (" << p.x() << ", " << p.y() << ", " << p.z()
              << ") lies " << (std::isfinite(nearest_m) ? std::to_string(nearest_m) + " m" : std::string("far"))
              << " outside the tet mesh (at most " << max_outside_m << " m)";
      throw MeshError(message.str(), source_name, 0, static_cast<int>(v + 1));
    }
  }
  return embedding;
}

EmbeddedSurface::EmbeddedSurface(const TetMesh& mesh, TriangleSurface surface, double max_outside_m,
                                 const std::string& source_name)
    : m_mesh(mesh),
      m_surface(std::move(surface)),
      m_embedding(embed_surface(m_mesh, m_surface, max_outside_m, source_name)),
      m_positions_m(m_surface.vertices_m.size(), Eigen::Vector3d::Zero()),
      m_normals(m_surface.vertices_m.size(), Eigen::Vector3d::Zero()) {}

void EmbeddedSurface::update(const Eigen::VectorXd& vertex_positions_m) {
  if (vertex_positions_m.size() < 3L * m_mesh.vertex_count()) {
    throw std::invalid_argument("render surface: " + std::to_string(vertex_positions_m.size()) +
                                " coordinates for a mesh of " + std::to_string(m_mesh.vertex_count()) + " vertices");
  }
  for (size_t v = 0; v < m_embedding.size(); ++v) {
    const SurfaceEmbedding& e = m_embedding[v];
    const Tet& tet = m_mesh.tets[static_cast<size_t>(e.tet)];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) x += e.weights(k) * vertex_positions_m.segment<3>(3 * tet[static_cast<size_t>(k)]);
    m_positions_m[v] = x;
  }
  vertex_normals(m_positions_m, m_surface.triangles, m_normals);
}

void vertex_normals(const std::vector<Eigen::Vector3d>& positions_m, const std::vector<std::array<int, 3>>& triangles,
                    std::vector<Eigen::Vector3d>& normals) {
  normals.resize(positions_m.size());
  for (Eigen::Vector3d& n : normals) n.setZero();
  for (const auto& [a, b, c] : triangles) {
    const Eigen::Vector3d area_normal = (positions_m[static_cast<size_t>(b)] - positions_m[static_cast<size_t>(a)])
                                            .cross(positions_m[static_cast<size_t>(c)] - positions_m[static_cast<size_t>(a)]);
    normals[static_cast<size_t>(a)] += area_normal;
    normals[static_cast<size_t>(b)] += area_normal;
    normals[static_cast<size_t>(c)] += area_normal;
  }
  for (Eigen::Vector3d& n : normals) {
    const double length = n.norm();
    if (length > 0.0) n /= length;
  }
}

}  // namespace tissue
