// A closed box surface for the render-surface tests: `n` squares along each edge of each face.
#pragma once

#include "core/render/embedded_surface.hpp"

#include <cmath>
#include <map>
#include <tuple>

namespace tissue {

/// The box [0, size] with `n` squares along each edge of each face (two triangles each), outward.
inline TriangleSurface box_surface(const Eigen::Vector3d& size_m, int n) {
  TriangleSurface surface;
  std::map<std::tuple<long, long, long>, int> index;
  const auto vertex = [&](const Eigen::Vector3d& p) {
    const auto key = std::make_tuple(std::lround(p.x() * 1e9), std::lround(p.y() * 1e9), std::lround(p.z() * 1e9));
    const auto [it, added] = index.emplace(key, static_cast<int>(surface.vertices_m.size()));
    if (added) surface.vertices_m.push_back(p);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int high = 0; high < 2; ++high) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      Eigen::Vector3d origin = Eigen::Vector3d::Zero();
      origin(axis) = high != 0 ? size_m(axis) : 0.0;
      const auto corner = [&](int i, int j) {
        Eigen::Vector3d p = origin;
        p(u) = size_m(u) * i / n;
        p(w) = size_m(w) * j / n;
        return vertex(p);
      };
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          const int a = corner(i, j), b = corner(i + 1, j), c = corner(i + 1, j + 1), d = corner(i, j + 1);
          // e_u x e_w = e_axis: counter-clockwise seen from +axis, outward on the high face.
          if (high != 0) {
            surface.triangles.push_back({a, b, c});
            surface.triangles.push_back({a, c, d});
          } else {
            surface.triangles.push_back({a, c, b});
            surface.triangles.push_back({a, d, c});
          }
        }
      }
    }
  }
  return surface;
}

}  // namespace tissue
