// CutSurface (see cut_surface.hpp).
#include "core/cut/cut_surface.hpp"

#include "core/mesh/topology.hpp"

#include <Eigen/Geometry>

#include <algorithm>

namespace tissue {

namespace {

// The crossing on the local edge a-b as a ratio from a: edge_ratio is stored along TET_EDGES' order.
double ratio_from(const TetCut& cut, int a, int b) {
  for (int e = 0; e < 6; ++e) {
    const auto& edge = TET_EDGES[static_cast<size_t>(e)];
    if (edge[0] == a && edge[1] == b) return cut.edge_ratio[static_cast<size_t>(e)];
    if (edge[0] == b && edge[1] == a) return 1.0 - cut.edge_ratio[static_cast<size_t>(e)];
  }
  return 0.5;  // unreachable for two distinct local vertices
}

}  // namespace

int CutSurface::add_cut_tets(const DeformableBody& body, int first_cut_tet, const SurfaceMesh& surface) {
  const auto& cut_tets = body.cut_tets();
  const TetMesh& mesh = body.mesh();
  const int triangles_before = static_cast<int>(m_triangles.size());
  for (int k = first_cut_tet; k < static_cast<int>(cut_tets.size()); ++k) {
    const TetCut& cut = cut_tets[static_cast<size_t>(k)].cut;
    const Tet& tet = mesh.tets[static_cast<size_t>(cut.tet)];
    // The crossed edges between the two groups, ordered around the polygon: walk from edge to edge
    // through shared triangles (for a 2-2 split {a,b}|{c,d}: ac, ad, bd, bc).
    std::vector<int> crossed;
    for (int e = 0; e < 6; ++e) {
      const auto& edge = TET_EDGES[static_cast<size_t>(e)];
      if (cut.side[static_cast<size_t>(edge[0])] != cut.side[static_cast<size_t>(edge[1])]) crossed.push_back(e);
    }
    if (crossed.size() == 4) {
      // Two crossed edges are consecutive when they share a vertex; reorder into a cycle.
      const auto shares = [](int e, int f) {
        const auto& a = TET_EDGES[static_cast<size_t>(e)];
        const auto& b = TET_EDGES[static_cast<size_t>(f)];
        return a[0] == b[0] || a[0] == b[1] || a[1] == b[0] || a[1] == b[1];
      };
      if (!shares(crossed[0], crossed[1])) std::swap(crossed[1], crossed[2]);
      if (!shares(crossed[1], crossed[2])) std::swap(crossed[2], crossed[3]);
    }
    // Rest-state corners and the outward normal of part "above" (toward the below vertices).
    std::vector<Eigen::Vector3d> rest;
    Eigen::Vector3d above_centre = Eigen::Vector3d::Zero();
    Eigen::Vector3d below_centre = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3d& x = mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(i)])];
      (cut.side[static_cast<size_t>(i)] > 0 ? above_centre : below_centre) += x;
    }
    for (int e : crossed) {
      const auto& edge = TET_EDGES[static_cast<size_t>(e)];
      const double r = cut.edge_ratio[static_cast<size_t>(e)];
      rest.push_back((1.0 - r) * mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(edge[0])])] +
                     r * mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(edge[1])])]);
    }
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // of the polygon in the order of `crossed`
    for (size_t p = 0; p < rest.size(); ++p) normal += rest[p].cross(rest[(p + 1) % rest.size()]);
    int above_count = 0;
    for (auto s : cut.side) above_count += s > 0 ? 1 : 0;
    const Eigen::Vector3d above_to_below = below_centre / (4 - above_count) - above_centre / above_count;
    const bool polygon_faces_below = normal.dot(above_to_below) >= 0.0;

    for (CutPart part : {CutPart::above, CutPart::below}) {
      const int first_point = m_vertex_count + static_cast<int>(m_points.size());
      for (int e : crossed) {
        const auto& edge = TET_EDGES[static_cast<size_t>(e)];
        m_points.push_back(Point{k, part, edge[0], edge[1], cut.edge_ratio[static_cast<size_t>(e)]});
      }
      // Outward from the part: toward below for part above, toward above for part below.
      const bool keep_order = (part == CutPart::above) == polygon_faces_below;
      const int n = static_cast<int>(crossed.size());
      for (int t = 1; t + 1 < n; ++t) {
        std::array<int, 3> triangle{first_point, first_point + t, first_point + t + 1};
        if (!keep_order) std::swap(triangle[1], triangle[2]);
        m_triangles.push_back(triangle);
      }
    }

    // The skin: the tet's surface triangles (triangle_tet is in tet order), split along the cut.
    const auto [first, last] = std::equal_range(surface.triangle_tet.begin(), surface.triangle_tet.end(), cut.tet);
    for (auto it = first; it != last; ++it) {
      const int triangle_index = static_cast<int>(it - surface.triangle_tet.begin());
      const std::array<int, 3>& triangle = surface.triangles[static_cast<size_t>(triangle_index)];
      std::array<int, 3> local{};
      for (int c = 0; c < 3; ++c) {
        for (int i = 0; i < 4; ++i) {
          if (tet[static_cast<size_t>(i)] == triangle[static_cast<size_t>(c)]) local[static_cast<size_t>(c)] = i;
        }
      }
      m_replaced.insert(std::upper_bound(m_replaced.begin(), m_replaced.end(), triangle_index), triangle_index);
      for (CutPart part : {CutPart::above, CutPart::below}) {
        const int side = part == CutPart::above ? 1 : -1;
        std::vector<int> polygon;  // walked in the triangle's order, so the winding stays outward
        for (int c = 0; c < 3; ++c) {
          const int a = local[static_cast<size_t>(c)];
          const int b = local[static_cast<size_t>((c + 1) % 3)];
          if (cut.side[static_cast<size_t>(a)] == side) polygon.push_back(triangle[static_cast<size_t>(c)]);
          if (cut.side[static_cast<size_t>(a)] != cut.side[static_cast<size_t>(b)]) {
            polygon.push_back(m_vertex_count + static_cast<int>(m_points.size()));
            m_points.push_back(Point{k, part, a, b, ratio_from(cut, a, b)});
          }
        }
        for (size_t t = 1; t + 1 < polygon.size(); ++t) m_skin.push_back({polygon[0], polygon[t], polygon[t + 1]});
      }
    }
  }
  m_cut_tets = static_cast<int>(cut_tets.size());
  return static_cast<int>(m_triangles.size()) - triangles_before;
}

void CutSurface::update_points(const DeformableBody& body, const Eigen::VectorXd& displacement_m,
                               Eigen::VectorXd& positions_m) const {
  positions_m.conservativeResize(3 * (m_vertex_count + point_count()));
  int last_cut_tet = -1;
  CutPart last_part = CutPart::above;
  TetPositions part_positions;
  for (size_t p = 0; p < m_points.size(); ++p) {
    const Point& point = m_points[p];
    if (point.cut_tet != last_cut_tet || point.part != last_part) {
      part_positions = body.part_positions(displacement_m, point.cut_tet, point.part);
      last_cut_tet = point.cut_tet;
      last_part = point.part;
    }
    positions_m.segment<3>(3 * (m_vertex_count + static_cast<Eigen::Index>(p))) =
        (1.0 - point.ratio) * part_positions[static_cast<size_t>(point.from)] +
        point.ratio * part_positions[static_cast<size_t>(point.to)];
  }
}

}  // namespace tissue
