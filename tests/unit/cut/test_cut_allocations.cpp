// Real-time discipline (STYLE.md principle 6): after construction, cutter steps allocate nothing,
// also while they cut many tets. Counts every global operator new in this executable.
#include "core/collide/surface_bvh.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "support/counting_new.hpp"

#include <gtest/gtest.h>

#include <atomic>

namespace tissue {
namespace {

TEST(CutAllocations, CutterStepsAllocateNothing) {
  const TetMesh mesh = read_mesh(std::filesystem::path(TISSUE_MESH_DIR) / "frog.veg");
  const SurfaceMesh surface = extract_surface(mesh);
  const TetAdjacency adjacency = build_adjacency(mesh);
  Eigen::VectorXd positions(3 * mesh.vertex_count());
  for (int v = 0; v < mesh.vertex_count(); ++v)
    positions.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<std::size_t>(v)];
  const SurfaceBvh bvh(surface.triangles, positions);
  VolumeCutter cutter(mesh, adjacency, surface);

  // A long blade swept across the frog in 30 steps (fast enough to cut many tets per step), then
  // back, turned 8.5 degrees out of the first plane, through the cut tets (second cuts, cutting them
  // again), then out.
  const auto blade_at = [](double x, double tilt_m) {
    return Blade{Eigen::Vector3d(x, 0.004 - tilt_m, -0.2), Eigen::Vector3d(x + 0.003, -0.002 + tilt_m, 0.2)};
  };
  const long before = g_allocations.load();
  int cut_tets = 0;
  for (const double direction : {1.0, -1.0}) {
    const double tilt_m = direction > 0.0 ? 0.0 : 0.03;  // turned about the blade's middle
    for (int i = 0; i < 30; ++i) {
      const double x0 = direction * (-0.1 + 0.2 * i / 30.0);
      const double x1 = direction * (-0.1 + 0.2 * (i + 1) / 30.0);
      const CutStepReport report = cutter.step(blade_at(x0, tilt_m), blade_at(x1, tilt_m), positions, bvh);
      cut_tets += report.newly_cut_tets;
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(cut_tets, 100);  // the steps did cut
  int recut = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) recut += cutter.cut_count(t) > 1 ? 1 : 0;
  EXPECT_GT(recut, 100);
}

}  // namespace
}  // namespace tissue
