// Real-time discipline (STYLE.md principle 6) with cuts and contact: once a body has been cut and
// the point spring set, a backward-Euler step with PCG allocates nothing after the first. Counts
// every global operator new in this executable.
#include "core/contact/point_spring.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/integrate/backward_euler.hpp"
#include "core/mesh/box_mesh.hpp"
#include "fem/xfem_test_helpers.hpp"
#include "support/counting_new.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <memory>

namespace tissue {
namespace {

TEST(XfemAllocations, StepOfACutBodyWithAPointSpringAllocatesNothing) {
  const TetMesh mesh = make_box_mesh(12, 3, 3, 0.01);
  BodySettings settings;
  settings.damping = {0.5, 0.01};
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<size_t>(v)].x() < 1e-9) settings.fixed_vertices.push_back(v);
  }
  DeformableBody body(mesh, settings);
  const Tet& tet = mesh.tets.back();
  PointSpringTerm spring;
  body.attach(spring);
  spring.set(PointSpring{{tet[0], tet[1], tet[2]}, Eigen::Vector3d::Constant(1.0 / 3.0), Eigen::Vector3d(0.13, 0.02, 0.02),
                         100.0},
             body.term_layout());
  DynamicState state{Eigen::VectorXd::Zero(body.dof_count()), Eigen::VectorXd::Zero(body.dof_count())};
  BackwardEuler integrator(std::make_unique<PcgSolver>(PcgSolver::Settings{1e-3, 10}));
  integrator.step(body, state, 0.01);

  const auto cuts = xfem_test::plane_cuts(mesh, xfem_test::Plane{Eigen::Vector3d(1, 0.1, 0.05).normalized(), 0.063});
  ASSERT_GT(cuts.size(), 20u);
  body.enrich(cuts);  // may re-lay the tangent out (rows start compact); the steps after must not allocate
  body.grow_state(state);
  integrator.step(body, state, 0.01);  // sizes the work buffers to the grown system
  // The body's parts are found once after a cut, when first asked for (by Tissue's look for parts
  // out of the field, or the energy guard's first scaling): asked here. The guard's own lists are
  // reserved with the system (found when the steps' path changed and step 17 scaled first).
  ASSERT_NE(body.row_parts(), nullptr);
  const long before = g_allocations.load();
  for (int i = 0; i < 20; ++i) integrator.step(body, state, 0.01);
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_TRUE(state.displacement_m.allFinite());
}

}  // namespace
}  // namespace tissue
