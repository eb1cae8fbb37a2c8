// Real-time discipline (STYLE.md principle 6): SurfaceBvh::refit and the queries allocate nothing
// once the caller's hit vectors have their capacity. Counts every global operator new in this executable.
#include "core/collide/surface_bvh.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/topology.hpp"
#include "support/counting_new.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

namespace tissue {
namespace {

TEST(SurfaceBvhAllocations, RefitAndQueriesAllocateNothing) {
  const TetMesh mesh = make_box_mesh(10, 4, 4, 0.01);
  Eigen::VectorXd rest(3 * static_cast<Eigen::Index>(mesh.vertex_count()));
  for (int v = 0; v < mesh.vertex_count(); ++v)
    rest.segment<3>(3 * static_cast<Eigen::Index>(v)) = mesh.rest_positions_m[static_cast<size_t>(v)];
  SurfaceBvh bvh(extract_surface(mesh).triangles, rest);
  Eigen::VectorXd deformed = rest;
  std::vector<SurfaceBvh::SegmentHit> segment_hits;
  std::vector<SurfaceBvh::SphereHit> sphere_hits;
  std::vector<int> box_hits;
  segment_hits.reserve(static_cast<size_t>(bvh.triangle_count()));
  sphere_hits.reserve(static_cast<size_t>(bvh.triangle_count()));
  box_hits.reserve(static_cast<size_t>(bvh.triangle_count()));

  const long before = g_allocations.load();
  int found = 0;
  for (int step = 0; step < 20; ++step) {
    for (Eigen::Index i = 0; i < rest.size(); i += 3) {
      deformed[i + 1] = rest[i + 1] + 0.002 * std::sin(0.1 * step + 30.0 * rest[i]);  // bending along x
    }
    bvh.refit(deformed);
    const Eigen::Vector3d tip(0.005 * step, 0.02, 0.05);
    bvh.intersect_segment(tip, tip - Eigen::Vector3d(0.0, 0.0, 0.1), deformed, segment_hits);
    bvh.intersect_sphere({0.05, 0.0, 0.02}, 0.01, deformed, sphere_hits);
    bvh.overlap_box({0.0, -0.01, 0.0}, {0.05, 0.01, 0.04}, box_hits);
    found += static_cast<int>(segment_hits.size() + sphere_hits.size() + box_hits.size());
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(found, 40);  // the queries did find triangles (top and bottom faces, side face, boxes)
}

}  // namespace
}  // namespace tissue
