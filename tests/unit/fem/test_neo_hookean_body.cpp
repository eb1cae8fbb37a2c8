// The stable Neo-Hookean model in a whole body (issue 25): a rigid motion gives no force, the
// forces are the energy's gradient and the assembled tangent its Hessian (finite differences, at a
// state where the element tangents need no projection), small deformations agree with
// co-rotational linear elasticity to first order, and inverted tets recover under backward Euler
// and IDA alike.
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <functional>

namespace tissue {
namespace {

BodySettings neo_hookean_settings(const TetMesh& mesh) {
  BodySettings s;
  s.material = Material{1.0e5, 0.4, 1000.0};
  s.material_model = MaterialModel::stable_neo_hookean;
  s.gravity_m_per_s2.setZero();
  s.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
  return s;
}

// Displacements of the free unknowns for positions given per vertex.
Eigen::VectorXd displacement_for(const DeformableBody& body,
                                 const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& to) {
  Eigen::VectorXd u(body.dof_count());
  for (int row = 0; row < body.dofs().free_vertex_count(); ++row) {
    const Eigen::Vector3d& x =
        body.mesh().rest_positions_m[static_cast<size_t>(body.dofs().row_vertex[static_cast<size_t>(row)])];
    u.segment<3>(3 * row) = to(x) - x;
  }
  return u;
}

TEST(NeoHookeanBody, ARigidMotionGivesNoForce) {
  TetMesh mesh = make_box_mesh(4, 2, 2, 0.01);
  BodySettings settings = neo_hookean_settings(mesh);
  settings.fixed_vertices.clear();
  settings.fixed_vertices.push_back(0);  // the body needs no support for a force evaluation
  DeformableBody body(mesh, settings);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(1.9, Eigen::Vector3d(0.3, -1, 0.4).normalized()).toRotationMatrix();
  // Vertex 0 (fixed) is at the origin: rotate about it.
  const Eigen::VectorXd u = displacement_for(body, [&](const Eigen::Vector3d& x) { return Eigen::Vector3d(r * x); });
  Eigen::VectorXd f;
  body.evaluate(u, f, false);
  // A 1% strain would give forces of ~E * 0.01 * (1 cm)^2 = 0.1 N; a rigid motion's are round-off.
  EXPECT_LT(f.cwiseAbs().maxCoeff(), 1e-10);
}

TEST(NeoHookeanBody, ForcesAndTangentAreTheEnergysDerivatives) {
  TetMesh mesh = make_box_mesh(4, 2, 2, 0.01);
  DeformableBody body(mesh, neo_hookean_settings(mesh));
  // A smooth stretch and shear of 10%: every element tangent is positive definite there (checked
  // below through the projection changing nothing), so the assembled tangent is the exact Hessian.
  const Eigen::VectorXd u = displacement_for(body, [](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(1.1 * x.x() + 0.05 * x.y(), x.y() + 0.03 * x.x(), 0.97 * x.z());
  });
  Eigen::VectorXd f;
  body.evaluate(u, f, true);
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(u.size(), u.size());
  const BlockSparseMatrix& tangent = body.tangent();
  for (int r = 0; r < tangent.block_rows(); ++r) {
    for (int slot = tangent.row_begin(r); slot < tangent.row_begin(r) + tangent.row_size(r); ++slot) {
      k.block<3, 3>(3 * r, 3 * tangent.slot_column(slot)) += tangent.block(slot);
    }
  }
  const double h = 1e-8;
  Eigen::MatrixXd k_numeric(u.size(), u.size());
  Eigen::VectorXd f_numeric(u.size());
  for (Eigen::Index j = 0; j < u.size(); ++j) {
    Eigen::VectorXd plus = u, minus = u, fp, fm;
    plus(j) += h;
    minus(j) -= h;
    f_numeric(j) = (body.elastic_energy_j(plus) - body.elastic_energy_j(minus)) / (2.0 * h);
    body.evaluate(plus, fp, false);
    body.evaluate(minus, fm, false);
    k_numeric.col(j) = (fp - fm) / (2.0 * h);
  }
  EXPECT_LT((f_numeric - f).norm(), 1e-6 * f.norm());
  EXPECT_LT((k_numeric - k).norm(), 1e-6 * k.norm());
}

TEST(NeoHookeanBody, SmallDeformationsAgreeWithCorotationalLinearToFirstOrder) {
  TetMesh mesh = make_box_mesh(4, 2, 2, 0.01);
  BodySettings linear_settings = neo_hookean_settings(mesh);
  linear_settings.material_model = MaterialModel::corotational_linear;
  DeformableBody neo_hookean(mesh, neo_hookean_settings(mesh));
  DeformableBody linear(mesh, linear_settings);
  std::vector<double> relative;
  for (const double eps : {1e-2, 5e-3, 2.5e-3}) {
    const Eigen::VectorXd u = displacement_for(neo_hookean, [&](const Eigen::Vector3d& x) {
      return Eigen::Vector3d(x.x() * (1.0 + eps), x.y() + eps * 0.5 * x.x(), x.z() * (1.0 - 0.4 * eps));
    });
    Eigen::VectorXd f_nh, f_lin;
    neo_hookean.evaluate(u, f_nh, false);
    linear.evaluate(u, f_lin, false);
    relative.push_back((f_nh - f_lin).norm() / f_lin.norm());
  }
  // Both are linear elasticity to first order: the forces differ by O(eps^2), relatively O(eps).
  EXPECT_LT(relative[0], 0.05);
  EXPECT_NEAR(relative[0] / relative[1], 2.0, 0.25);
  EXPECT_NEAR(relative[1] / relative[2], 2.0, 0.25);
}

// A beam's far top corner pushed 8 mm down through the tets below it (inverting them) and let go,
// no gravity: the tets must come back, every one positive again, under each integrator.
TEST(NeoHookeanBody, InvertedTetsRecoverUnderEachIntegrator) {
  for (const IntegratorKind kind : {IntegratorKind::backward_euler, IntegratorKind::ida}) {
    SCOPED_TRACE(kind == IntegratorKind::ida ? "ida" : "backward euler");
    TetMesh mesh = make_box_mesh(8, 2, 2, 0.005);
    TissueSettings settings;
    settings.body = neo_hookean_settings(mesh);
    settings.body.damping = RayleighDamping{5.0, 1e-3};
    settings.integrator.kind = kind;
    settings.solver.kind = LinearSolverKind::cholmod;
    settings.step_size_s = 0.01;
    Tissue tissue(mesh, settings);
    const int top = mesh.vertex_count() - 1;  // (8, 2, 2): x = 0.04, y = z = 0.01 m
    TissueSnapshot snapshot;
    tissue.save(snapshot);
    const int row = tissue.body().dofs().vertex_row[static_cast<size_t>(top)];
    ASSERT_GE(row, 0);
    snapshot.dynamics.displacement_m(3 * row + 2) = -0.008;
    snapshot.integrator_state.resize(0);  // the integrator starts afresh from the pushed state
    tissue.restore(snapshot);
    const auto inverted_tets = [&] {
      Eigen::VectorXd x;
      tissue.vertex_positions(x);
      int inverted = 0;
      for (const Tet& t : mesh.tets) {
        const auto p = [&](int v) { return Eigen::Vector3d(x.segment<3>(3 * v)); };
        if (signed_tet_volume(p(t[0]), p(t[1]), p(t[2]), p(t[3])) <= 0.0) ++inverted;
      }
      return inverted;
    };
    const int before = inverted_tets();
    ASSERT_GT(before, 0);
    for (int step = 0; step < 100; ++step) tissue.step();
    EXPECT_EQ(inverted_tets(), 0);
    Eigen::VectorXd x;
    tissue.vertex_positions(x);
    EXPECT_NEAR(x(3 * top + 2), mesh.rest_positions_m[static_cast<size_t>(top)].z(), 1e-4);  // back at rest
  }
}

}  // namespace
}  // namespace tissue
