// Tests of the point spring through which god-object contact pulls the body: its force and tangent
// against the definition and finite differences, the static pull of a clamped bar against two
// springs in series (the spring and the bar's compliance at the point, P^T K^-1 P), and the checks.
#include "core/contact/point_spring.hpp"
#include "core/fem/deformable_body.hpp"
#include "core/mesh/box_mesh.hpp"
#include "fem/xfem_test_helpers.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <iostream>
#include <limits>
#include <optional>
#include <vector>

namespace tissue {
namespace {

using xfem_test::dense;

// A bar of 1 cm cubes clamped at x = 0, no gravity.
struct Bar {
  TetMesh mesh;
  DeformableBody body;
  PointSpringTerm spring_term;  // attached to body

  Bar(int cubes, double young_modulus_pa)
      : mesh(make_box_mesh(cubes, 2, 2, 0.01)), body(mesh, settings(mesh, young_modulus_pa)) {
    body.attach(spring_term);
  }
  Bar(const Bar&) = delete;
  Bar& operator=(const Bar&) = delete;
  void set_point_spring(std::optional<PointSpring> s) { spring_term.set(std::move(s), body.term_layout()); }

  static BodySettings settings(const TetMesh& mesh, double young_modulus_pa) {
    BodySettings s;
    s.material = Material{young_modulus_pa, 0.3, 1000.0};
    s.gravity_m_per_s2.setZero();
    for (int v = 0; v < mesh.vertex_count(); ++v) {
      if (mesh.rest_positions_m[static_cast<size_t>(v)].x() < 1e-9) s.fixed_vertices.push_back(v);
    }
    return s;
  }
  // Three vertices of one tet, all with rest x equal to `x_m` when possible: a surface triangle.
  std::array<int, 3> face_at(double x_m) const {
    for (const Tet& tet : mesh.tets) {
      std::array<int, 3> face{};
      int count = 0;
      for (int v : tet) {
        if (count < 3 && std::abs(mesh.rest_positions_m[static_cast<size_t>(v)].x() - x_m) < 1e-9)
          face[static_cast<size_t>(count++)] = v;
      }
      if (count == 3) return face;
    }
    throw std::logic_error("no face at that x");
  }
  Eigen::Vector3d point(const PointSpring& spring, const Eigen::VectorXd& positions_m) const {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i)
      p += spring.weights(i) * positions_m.segment<3>(3 * spring.vertices[static_cast<size_t>(i)]);
    return p;
  }
};

TEST(PointSpring, ForceAndTangentMatchTheDefinitionAndFiniteDifferences) {
  Bar bar(3, 1e5);
  // A triangle on the clamped face x = 0 shares a tet with free vertices; take one with a fixed vertex
  // (its share is skipped, but it still places x_p) and one fully free.
  for (const double face_x : {0.0, 0.03}) {
    std::array<int, 3> triangle = bar.face_at(face_x);
    if (face_x == 0.0) {
      // Swap one clamped vertex for a free vertex of the same tet.
      for (const Tet& tet : bar.mesh.tets) {
        int hits = 0;
        for (int v : tet) hits += v == triangle[0] || v == triangle[1];
        if (hits < 2) continue;
        for (int v : tet) {
          if (bar.body.dofs().vertex_row[static_cast<size_t>(v)] >= 0) triangle[2] = v;
        }
        break;
      }
    }
    const PointSpring spring{triangle, Eigen::Vector3d(0.2, 0.3, 0.5), Eigen::Vector3d(0.02, 0.013, 0.007), 250.0};
    Eigen::VectorXd u(bar.body.dof_count());
    for (Eigen::Index k = 0; k < u.size(); ++k) u(k) = 3e-4 * std::sin(1.3 * static_cast<double>(k));

    Eigen::VectorXd f_without;
    bar.set_point_spring(std::nullopt);
    bar.body.evaluate(u, f_without, true);
    const Eigen::MatrixXd k_without = dense(bar.body.tangent());
    bar.set_point_spring(spring);
    Eigen::VectorXd f_with;
    bar.body.evaluate(u, f_with, true);
    const Eigen::MatrixXd k_spring = dense(bar.body.tangent()) - k_without;
    const Eigen::VectorXd f_spring = f_with - f_without;

    Eigen::VectorXd positions;
    bar.body.positions(u, positions);
    const Eigen::Vector3d stretch = bar.point(spring, positions) - spring.target_m;
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(u.size());
    for (int i = 0; i < 3; ++i) {
      const int row = bar.body.dofs().vertex_row[static_cast<size_t>(spring.vertices[static_cast<size_t>(i)])];
      if (row >= 0) expected.segment<3>(3 * row) += spring.stiffness_n_per_m * spring.weights(i) * stretch;
    }
    // Sums of a few products: round-off only, relative to the elastic forces they were added to.
    EXPECT_LT((f_spring - expected).norm(), 1e-12 * f_with.norm());
    EXPECT_LT((bar.spring_term.force_on_body_n() + spring.stiffness_n_per_m * stretch).norm(),
              1e-12 * stretch.norm() * spring.stiffness_n_per_m);

    // The spring is linear in u: central differences are exact up to round-off of f_int (~1e-16 |f|
    // / step with |f| ~ 1 N and step 1e-6 m: 1e-10 N/m), far below k w_i w_j ~ 10 N/m.
    const double step_m = 1e-6;
    Eigen::MatrixXd numeric(u.size(), u.size());
    for (Eigen::Index k = 0; k < u.size(); ++k) {
      Eigen::VectorXd plus = u;
      Eigen::VectorXd minus = u;
      plus(k) += step_m;
      minus(k) -= step_m;
      Eigen::VectorXd f_plus;
      Eigen::VectorXd f_minus;
      bar.body.evaluate(plus, f_plus, false);
      bar.body.evaluate(minus, f_minus, false);
      bar.set_point_spring(std::nullopt);
      Eigen::VectorXd e_plus;
      Eigen::VectorXd e_minus;
      bar.body.evaluate(plus, e_plus, false);
      bar.body.evaluate(minus, e_minus, false);
      bar.set_point_spring(spring);
      numeric.col(k) = ((f_plus - e_plus) - (f_minus - e_minus)) / (2.0 * step_m);
    }
    EXPECT_LT((numeric - k_spring).norm(), 1e-6 * k_spring.norm());
    EXPECT_GT(k_spring.norm(), 0.0);

    // A tangent fraction c scales the spring's tangent only (the undamped contact spring).
    PointSpring shared = spring;
    shared.tangent_fraction = 0.25;
    bar.set_point_spring(shared);
    Eigen::VectorXd f_shared;
    bar.body.evaluate(u, f_shared, true);
    EXPECT_LT((f_shared - f_with).norm(), 1e-12 * f_with.norm());
    EXPECT_LT(((dense(bar.body.tangent()) - k_without) - 0.25 * k_spring).norm(), 1e-6 * k_spring.norm());

    // Along a direction d alone (the sliding contact): force k d d^T (x_p - target), tangent
    // k w_i w_j d d^T, energy k/2 (d . (x_p - target))^2, whose gradient the force is.
    PointSpring along = spring;
    along.direction = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
    bar.set_point_spring(along);
    Eigen::VectorXd f_along;
    bar.body.evaluate(u, f_along, true);
    const Eigen::Matrix3d projector = along.direction * along.direction.transpose();
    Eigen::VectorXd expected_along = Eigen::VectorXd::Zero(u.size());
    Eigen::MatrixXd expected_tangent = Eigen::MatrixXd::Zero(u.size(), u.size());
    for (int i = 0; i < 3; ++i) {
      const int row = bar.body.dofs().vertex_row[static_cast<size_t>(spring.vertices[static_cast<size_t>(i)])];
      if (row < 0) continue;
      expected_along.segment<3>(3 * row) += spring.stiffness_n_per_m * spring.weights(i) * (projector * stretch);
      for (int j = 0; j < 3; ++j) {
        const int col = bar.body.dofs().vertex_row[static_cast<size_t>(spring.vertices[static_cast<size_t>(j)])];
        if (col >= 0) {
          expected_tangent.block<3, 3>(3 * row, 3 * col) +=
              spring.stiffness_n_per_m * spring.weights(i) * spring.weights(j) * projector;
        }
      }
    }
    EXPECT_LT(((f_along - f_without) - expected_along).norm(), 1e-12 * f_with.norm());
    EXPECT_LT(((dense(bar.body.tangent()) - k_without) - expected_tangent).norm(), 1e-9 * k_spring.norm());
    EXPECT_NEAR(bar.spring_term.energy_j(positions),
                0.5 * spring.stiffness_n_per_m * std::pow(along.direction.dot(stretch), 2), 1e-15);
    along.direction *= 1.01;  // not a unit vector: refused, the spring kept
    EXPECT_THROW(bar.spring_term.set(along, bar.body.term_layout()), ParameterError);
    ASSERT_TRUE(bar.spring_term.spring().has_value());
    EXPECT_EQ(bar.spring_term.spring()->direction, along.direction / 1.01);
  }
}

// The terms' product (ForceTerm::add_tangent_product) is the spring's blocks of the tangent times a
// vector, with the tangent fraction and a direction, for a spring with a fixed vertex and a pad: the
// step's stiffness damping takes it out of beta K v, so it must be the very blocks add_tangent entered.
TEST(PointSpring, TheTermsProductIsItsBlocksOfTheTangentTimesTheVector) {
  Bar bar(3, 1e5);
  Eigen::VectorXd u(bar.body.dof_count()), v(bar.body.dof_count());
  for (Eigen::Index k = 0; k < u.size(); ++k) {
    u(k) = 3e-4 * std::sin(1.3 * static_cast<double>(k));
    v(k) = std::cos(0.7 * static_cast<double>(k));
  }
  Eigen::VectorXd force;
  bar.set_point_spring(std::nullopt);
  // Both evaluations from the same rotation warm starts (an evaluate moves them).
  DeformableBody::Rotations warm_starts;
  bar.body.save_rotations(warm_starts);
  bar.body.evaluate(u, force, true);
  const Eigen::MatrixXd k_without = dense(bar.body.tangent());
  Eigen::VectorXd none = Eigen::VectorXd::Zero(v.size());
  bar.body.add_force_terms_tangent_product(v, none);
  EXPECT_EQ(none.norm(), 0.0);  // an idle term adds nothing

  std::array<int, 3> held{-1, -1, -1};  // one clamped vertex and two free ones of a tet
  for (const Tet& tet : bar.mesh.tets) {
    std::vector<int> fixed, free;
    for (int vertex : tet)
      (bar.body.dofs().vertex_row[static_cast<size_t>(vertex)] < 0 ? fixed : free).push_back(vertex);
    if (!fixed.empty() && free.size() >= 2) {
      held = {free[0], fixed[0], free[1]};
      break;
    }
  }
  ASSERT_GE(held[1], 0);
  PointSpring spring{held, Eigen::Vector3d(0.2, 0.3, 0.5), Eigen::Vector3d(0.02, 0.013, 0.007), 250.0};
  spring.tangent_fraction = 0.4;
  PointSpring pad = spring;
  pad.vertices = bar.face_at(0.03);
  pad.stiffness_n_per_m = 40.0;
  pad.direction = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
  bar.spring_term.set(spring, bar.body.term_layout(), {pad});
  bar.body.restore_rotations(warm_starts);
  bar.body.evaluate(u, force, true);
  const Eigen::VectorXd expected = (dense(bar.body.tangent()) - k_without) * v;
  Eigen::VectorXd product = Eigen::VectorXd::Constant(v.size(), 1.0);  // it adds
  bar.body.add_force_terms_tangent_product(v, product);
  ASSERT_GT(expected.norm(), 1.0);
  EXPECT_LT((product - Eigen::VectorXd::Constant(v.size(), 1.0) - expected).norm(), 1e-12 * expected.norm());
}

// A pad's springs (point_contact.hpp, "A pad") beside the point's: each acts as if it were alone, so
// force, tangent, energy and the force on the body are the sums of the springs' own.
TEST(PointSpring, APadsSpringsActAsIfEachWereAlone) {
  Bar bar(3, 1e5);
  const PointSpring centre{
      bar.face_at(0.02),       Eigen::Vector3d(0.2, 0.3, 0.5), Eigen::Vector3d(0.02, 0.013, 0.007), 250.0, 0.5,
      Eigen::Vector3d::UnitX()};
  PointSpring sample = centre;
  sample.vertices = bar.face_at(0.03);
  sample.weights = Eigen::Vector3d(0.6, 0.1, 0.3);
  sample.target_m = Eigen::Vector3d(0.031, 0.012, 0.009);
  sample.stiffness_n_per_m = 120.0;
  Eigen::VectorXd u(bar.body.dof_count());
  for (Eigen::Index k = 0; k < u.size(); ++k) u(k) = 3e-4 * std::cos(0.7 * static_cast<double>(k));
  Eigen::VectorXd positions;
  bar.body.positions(u, positions);
  struct Effect {
    Eigen::VectorXd force;
    Eigen::MatrixXd tangent;
    double energy_j;
    Eigen::Vector3d on_body_n;
  };
  const auto effect = [&](std::optional<PointSpring> spring, std::vector<PointSpring> pad) {
    bar.spring_term.set(std::move(spring), bar.body.term_layout(), std::move(pad));
    Effect e;
    bar.body.evaluate(u, e.force, true);
    e.tangent = dense(bar.body.tangent());
    e.energy_j = bar.spring_term.energy_j(positions);
    e.on_body_n = bar.spring_term.force_on_body_n();
    return e;
  };
  const Effect none = effect(std::nullopt, {});
  const Effect centre_alone = effect(centre, {});
  const Effect sample_alone = effect(sample, {});
  const Effect both = effect(centre, {sample});
  EXPECT_LT(((both.force - none.force) - (centre_alone.force - none.force) - (sample_alone.force - none.force)).norm(),
            1e-12 * both.force.norm());
  EXPECT_LT(
      ((both.tangent - none.tangent) - (centre_alone.tangent - none.tangent) - (sample_alone.tangent - none.tangent))
          .norm(),
      1e-9 * (both.tangent - none.tangent).norm());
  EXPECT_NEAR(both.energy_j, centre_alone.energy_j + sample_alone.energy_j, 1e-15);
  EXPECT_LT((both.on_body_n - centre_alone.on_body_n - sample_alone.on_body_n).norm(), 1e-12);
  EXPECT_LT((springs_force_on_body_n(bar.spring_term.pad(), positions) - sample_alone.on_body_n).norm(), 1e-12);
  // A pad without the point's spring, or with a bad spring, is refused and the springs kept.
  EXPECT_THROW(bar.spring_term.set(std::nullopt, bar.body.term_layout(), {sample}), ParameterError);
  PointSpring bad = sample;
  bad.weights = Eigen::Vector3d(0.6, 0.6, 0.3);
  EXPECT_THROW(bar.spring_term.set(centre, bar.body.term_layout(), {sample, bad}), ParameterError);
  ASSERT_EQ(bar.spring_term.pad().size(), 1U);
  EXPECT_EQ(bar.spring_term.pad()[0].target_m, sample.target_m);
}

TEST(PointSpring, PullOnAClampedBarIsTwoSpringsInSeries) {
  // Static equilibrium of the bar pulled by the spring towards target = x_p0 + D: the point moves
  // by d = C F with C = P^T K^-1 P (the bar's compliance at the point, from the rest tangent), and
  // F = k (D - d), so F = (C + I/k)^-1 D. Linear elasticity holds to O(|D| / L) = 1e-4 (a 10 um
  // pull on a 10 cm bar): 1e-3 relative covers the geometric nonlinearity.
  Bar bar(10, 1e6);
  const std::array<int, 3> triangle = bar.face_at(0.1);  // on the free end
  const Eigen::Vector3d weights(0.25, 0.35, 0.4);

  Eigen::VectorXd force;
  bar.body.evaluate(Eigen::VectorXd::Zero(bar.body.dof_count()), force, true);
  const Eigen::MatrixXd k = dense(bar.body.tangent());
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(k.rows(), 3);
  for (int i = 0; i < 3; ++i) {
    const int row = bar.body.dofs().vertex_row[static_cast<size_t>(triangle[static_cast<size_t>(i)])];
    p.block<3, 3>(3 * row, 0) += weights(i) * Eigen::Matrix3d::Identity();
  }
  const Eigen::Matrix3d compliance = p.transpose() * k.ldlt().solve(p);

  const double spring_n_per_m = 2000.0;
  for (const Eigen::Vector3d& pull : {Eigen::Vector3d(1e-5, 0.0, 0.0), Eigen::Vector3d(0.0, 0.3e-5, -1e-5)}) {
    Eigen::VectorXd positions;
    bar.body.positions(Eigen::VectorXd::Zero(bar.body.dof_count()), positions);
    const PointSpring spring{triangle, weights, bar.point(PointSpring{triangle, weights, {}, 0.0}, positions) + pull,
                             spring_n_per_m};
    bar.set_point_spring(spring);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(bar.body.dof_count());
    xfem_test::solve_static(bar.body, u);
    bar.body.evaluate(u, force, false);
    const Eigen::Vector3d f = bar.spring_term.force_on_body_n();
    const Eigen::Vector3d expected = (compliance + Eigen::Matrix3d::Identity() / spring_n_per_m).inverse() * pull;
    EXPECT_LT((f - expected).norm(), 1e-3 * expected.norm());
    const int axis = pull.x() != 0.0 ? 0 : 2;
    std::cout << "pull along "
              << "xyz"[axis] << ": k_eff " << f(axis) / pull(axis) << " N/m, series of spring " << spring_n_per_m
              << " and bar 1/C = " << 1.0 / compliance(axis, axis) << " N/m; relative error "
              << (f - expected).norm() / expected.norm() << "\n";
  }
}

TEST(PointSpring, RefusesBadSpringsAndKeepsTheOldOne) {
  Bar bar(3, 1e5);
  const std::array<int, 3> triangle = bar.face_at(0.03);
  const PointSpring good{triangle, Eigen::Vector3d(0.2, 0.3, 0.5), Eigen::Vector3d(0.03, 0.0, 0.0), 10.0};
  bar.set_point_spring(good);
  const auto refused = [&](PointSpring bad) {
    EXPECT_THROW(bar.set_point_spring(bad), ParameterError);
    ASSERT_TRUE(bar.spring_term.spring().has_value());
    EXPECT_EQ(bar.spring_term.spring()->vertices, good.vertices);
  };
  PointSpring bad = good;
  bad.vertices[1] = bar.mesh.vertex_count();
  refused(bad);
  bad.vertices[1] = -1;
  refused(bad);
  bad = good;
  bad.vertices[1] = 1;  // at x = 0.01: shares no tet with the end face at x = 0.03
  refused(bad);
  bad = good;
  bad.weights = Eigen::Vector3d(0.2, 0.3, 0.4);
  refused(bad);
  bad.weights = Eigen::Vector3d(std::nan(""), 0.5, 0.5);
  refused(bad);
  bad = good;
  bad.target_m.x() = std::numeric_limits<double>::infinity();
  refused(bad);
  bad = good;
  bad.stiffness_n_per_m = -1.0;
  refused(bad);
  bad.stiffness_n_per_m = std::nan("");
  refused(bad);
  bad = good;
  for (const double fraction : {0.0, -0.5, 1.5, std::nan("")}) {
    bad.tangent_fraction = fraction;
    refused(bad);
  }

  Eigen::VectorXd f;
  bar.body.evaluate(Eigen::VectorXd::Zero(bar.body.dof_count()), f, false);
  EXPECT_GT(bar.spring_term.force_on_body_n().norm(), 0.0);
  bar.set_point_spring(std::nullopt);
  EXPECT_EQ(bar.spring_term.force_on_body_n().norm(), 0.0);
  bar.body.evaluate(Eigen::VectorXd::Zero(bar.body.dof_count()), f, false);
  EXPECT_LT(f.norm(), 1e-12);  // at rest, no gravity, no spring: only round-off of the rest shape
}

}  // namespace
}  // namespace tissue
