// Real-time discipline (STYLE.md principle 6): after the first step, a backward-Euler step with
// PCG allocates nothing. Counts every global operator new in this executable.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"
#include "support/counting_new.hpp"

#include <gtest/gtest.h>

#include <atomic>

namespace tissue {
namespace {

TEST(StepAllocations, BackwardEulerWithPcgAllocatesNothingAfterTheFirstStep) {
  TetMesh mesh = make_box_mesh(12, 3, 3, 0.01);
  TissueSettings settings;
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
  settings.body.damping = {0.5, 0.01};
  settings.solver.pcg = {1e-3, 10};
  settings.step_size_s = 0.01;
  Tissue tissue(std::move(mesh), settings);
  tissue.step();  // sizes the work buffers
  const long before = g_allocations.load();
  for (int i = 0; i < 20; ++i) tissue.step();
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace tissue
