// Tests of the contact stiffness models on the frog: the effectiveStatic K_c is the slope of the
// quasi-static reaction of the full model (finite differences of a bonded poke), symmetric positive
// definite; the elementLocal model is the repaired eq. 4.23 (the printed one gives zero force),
// and its ratio to the reference is measured; the step-matrix variant for an unsupported body;
// CHOLMOD's factor-once/solve-many.
#include "core/integrate/integrator.hpp"
#include "core/contact/contact_stiffness.hpp"
#include "core/contact/quasi_static_poke.hpp"

#include "contact/frog_scene.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cstdio>
#include <limits>

namespace tissue {
namespace {

using namespace contact_test;

struct FrogAtRest {
  TetMesh mesh = frog_mesh();
  SurfaceMesh surface = extract_surface(mesh);
  DeformableBody body{mesh, frog_settings(mesh)};
  Eigen::VectorXd rest = rest_positions(mesh);
  Eigen::VectorXd zero_diagonal;
  EffectiveContactStiffness effective;

  FrogAtRest() {
    Eigen::VectorXd force;
    body.evaluate(Eigen::VectorXd::Zero(body.dof_count()), force, /*update_tangent=*/true);
    effective.factorize(static_contact_system(body.tangent(), zero_diagonal));
  }
  ContactInterpolation interpolation(const SurfacePoint& point) const {
    return contact_interpolation(body.dofs(), surface.triangles[static_cast<size_t>(point.triangle)],
                                 point.barycentric);
  }
  Eigen::Vector3d position(const SurfacePoint& point) const {
    return surface_point_position_m(point, surface.triangles, rest);
  }
  Eigen::Vector3d normal(const SurfacePoint& point) const {
    return unit_normal(surface.triangles[static_cast<size_t>(point.triangle)], rest);
  }
  /// The force of the tool on the body when the bonded point is pushed to `target`.
  Eigen::Vector3d bonded_reaction(const SurfacePoint& point, const Eigen::Vector3d& target) {
    QuasiStaticPokeSettings settings;
    settings.friction = PokeFriction::bonded;
    const QuasiStaticPoke poke = quasi_static_poke(body, surface.triangles, point, target, settings);
    EXPECT_TRUE(poke.converged);
    return -poke.force_on_tool_n;
  }
};

double min_eigenvalue(const Eigen::Matrix3d& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues()[0];
}

TEST(EffectiveContactStiffness, IsTheSlopeOfTheQuasiStaticReactionOfTheFullModel) {
  FrogAtRest frog;
  for (const SurfacePoint& point : back_points(frog.surface, frog.rest)) {
    const std::optional<Eigen::Matrix3d> k_c = frog.effective.stiffness_n_per_m(frog.interpolation(point));
    ASSERT_TRUE(k_c.has_value());
    EXPECT_TRUE(k_c->allFinite());
    EXPECT_LE((*k_c - k_c->transpose()).norm(), 1e-14 * k_c->norm());
    EXPECT_GT(min_eigenvalue(*k_c), 0.0);

    // Central differences of the full nonlinear model's reaction: at rest the tangent is the exact
    // Jacobian (no stress, so dR/du adds nothing), and the O(eps^2) truncation is (eps/h)^2 ~ 1e-7
    // for eps = 1 um and elements of h ~ 3 mm.
    const double eps_m = 1e-6;
    const Eigen::Vector3d x = frog.position(point);
    Eigen::Matrix3d slope;
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d step = eps_m * Eigen::Vector3d::Unit(axis);
      slope.col(axis) = (frog.bonded_reaction(point, x + step) - frog.bonded_reaction(point, x - step)) / (2 * eps_m);
    }
    const double slope_error = (slope - *k_c).norm() / k_c->norm();
    EXPECT_LE(slope_error, 1e-6);

    // One-sided, a pure poke along the inward normal: K_c d is the reaction up to O(d / h).
    const Eigen::Vector3d n = frog.normal(point);
    std::printf("  contact triangle %d: |K_c| = %.4g N/m, n.K_c.n = %.4g N/m, central-difference error %.2e",
                point.triangle, k_c->norm(), normal_stiffness_n_per_m(*k_c, n), slope_error);
    const double depth_m = 1e-9;  // O(d / h) ~ 3e-7 (measured 3e-6 at 1e-7 m: linear in d)
    const Eigen::Vector3d d = -depth_m * n;
    const Eigen::Vector3d reaction = frog.bonded_reaction(point, x + d);
    const double error = (reaction - *k_c * d).norm() / reaction.norm();
    std::printf(", one-sided at %.0e m: %.2e\n", depth_m, error);
    EXPECT_LE(error, 1e-6);
  }
}

TEST(EffectiveContactStiffness, TakesTheContactSpringOutOfTheMatrix) {
  // While the contact spring is set, the body's tangent holds k w_i w_j I: K_c from that matrix must
  // still be the tissue's own, whether the spring sits at the point, elsewhere on its triangle, or
  // on another triangle (a proxy that moved since the tangent was assembled).
  FrogAtRest frog;
  const std::vector<SurfacePoint> points = back_points(frog.surface, frog.rest);
  const SurfacePoint point = points[0];
  const Eigen::Matrix3d k_c = *frog.effective.stiffness_n_per_m(frog.interpolation(point));
  const double k = 100.0 * contact_stiffness_scale_n_per_m(frog.body, frog.surface);
  PointSpringTerm spring_term;
  frog.body.attach(spring_term);
  for (const SurfacePoint& spring_at :
       {point, SurfacePoint{point.triangle, Eigen::Vector3d(0.6, 0.3, 0.1)}, points[1]}) {
    spring_term.set(PointSpring{frog.surface.triangles[static_cast<size_t>(spring_at.triangle)], spring_at.barycentric,
                                frog.position(spring_at), k},
                    frog.body.term_layout());
    Eigen::VectorXd force, diagonal;
    frog.body.evaluate(Eigen::VectorXd::Zero(frog.body.dof_count()), force, true);
    EffectiveContactStiffness with_spring;
    with_spring.factorize(static_contact_system(frog.body.tangent(), diagonal));
    const Eigen::Matrix3d naive = *with_spring.stiffness_n_per_m(frog.interpolation(point));
    if (spring_at.triangle == point.triangle && spring_at.barycentric == point.barycentric) {
      // Sherman-Morrison: the spring at the point itself adds exactly k I.
      EXPECT_LE((naive - k_c - k * Eigen::Matrix3d::Identity()).norm(), 1e-10 * k);
    }
    const Eigen::Matrix3d k_tissue =
        *with_spring.stiffness_n_per_m(frog.interpolation(point), frog.interpolation(spring_at), k);
    EXPECT_LE((k_tissue - k_c).norm(), 1e-9 * k_c.norm()) << "spring on triangle " << spring_at.triangle;
    std::printf("  spring (k = %.3g N/m) on triangle %d: K_c from the matrix with it %.2e off, naive %.2e off\n", k,
                spring_at.triangle, (k_tissue - k_c).norm() / k_c.norm(), (naive - k_c).norm() / k_c.norm());
    EXPECT_THROW((void)with_spring.stiffness_n_per_m(frog.interpolation(point), frog.interpolation(spring_at), -1.0),
                 std::invalid_argument);

    // A spring along one direction alone (the sliding contact, k d d^T): taken out the same way.
    PointSpring along{frog.surface.triangles[static_cast<size_t>(spring_at.triangle)], spring_at.barycentric,
                      frog.position(spring_at), k};
    along.direction = Eigen::Vector3d(0.3, -0.2, 0.9).normalized();
    spring_term.set(along, frog.body.term_layout());
    frog.body.evaluate(Eigen::VectorXd::Zero(frog.body.dof_count()), force, true);
    EffectiveContactStiffness with_along;
    with_along.factorize(static_contact_system(frog.body.tangent(), diagonal));
    const Eigen::Matrix3d k_tissue_along =
        *with_along.stiffness_n_per_m(frog.interpolation(point), frog.interpolation(spring_at), k, along.direction);
    EXPECT_LE((k_tissue_along - k_c).norm(), 1e-9 * k_c.norm()) << "along, on triangle " << spring_at.triangle;
    // Taken out as if isotropic instead, it is wrong by far more.
    const Eigen::Matrix3d wrong =
        *with_along.stiffness_n_per_m(frog.interpolation(point), frog.interpolation(spring_at), k);
    EXPECT_GT((wrong - k_c).norm(), 1e-3 * k_c.norm());
  }
  frog.body.detach(spring_term);
}

TEST(EffectiveContactStiffness, APointOnFixedVerticesOnlyIsRigid) {
  FrogAtRest frog;
  const std::vector<int>& fixed = frog.body.settings().fixed_vertices;
  const auto is_fixed = [&](int v) { return std::binary_search(fixed.begin(), fixed.end(), v); };
  int held = -1;
  for (size_t t = 0; t < frog.surface.triangles.size() && held < 0; ++t) {
    const auto& tri = frog.surface.triangles[t];
    if (is_fixed(tri[0]) && is_fixed(tri[1]) && is_fixed(tri[2])) held = static_cast<int>(t);
  }
  ASSERT_GE(held, 0) << "the tail should have a surface triangle with every vertex fixed";
  EXPECT_FALSE(frog.effective.stiffness_n_per_m(frog.interpolation({held, Eigen::Vector3d::Constant(1.0 / 3.0)})));
  EXPECT_THROW(frog.effective.stiffness_n_per_m(ContactInterpolation{{100000, -1, -1}, Eigen::Vector3d(1, 0, 0)}),
               std::invalid_argument);
}

TEST(ElementLocalContactStiffness, RepairsEq422AndIsMeasuredAgainstTheReference) {
  FrogAtRest frog;
  const LameParameters lame = frog.body.elasticity().lame()[0];
  for (const SurfacePoint& point : back_points(frog.surface, frog.rest)) {
    const int tet = frog.surface.triangle_tet[static_cast<size_t>(point.triangle)];
    const int opposite = frog.surface.triangle_local_face[static_cast<size_t>(point.triangle)];
    const TetRest& rest = frog.body.elasticity().rest(tet);

    // The erratum: u_d = [d d d d] is a rigid translation, K_e u_d = 0 for any d.
    const Matrix12d k_e = linear_stiffness_matrix(rest, lame);
    const Eigen::Vector3d d(1e-3, -2e-3, 0.5e-3);
    EXPECT_LE((k_e * d.replicate<4, 1>()).norm(), 1e-12 * k_e.norm() * d.norm());

    // The repair: the face pushed by d, the opposite vertex held; summed over the face, R K_oo R^T d.
    Vector12d u_face = d.replicate<4, 1>();
    u_face.segment<3>(3 * opposite).setZero();
    const Vector12d f = k_e * u_face;
    Eigen::Vector3d face_force = Eigen::Vector3d::Zero();
    for (int i = 0; i < 4; ++i) {
      if (i != opposite) face_force += f.segment<3>(3 * i);
    }
    const Eigen::Matrix3d k_local =
        element_local_contact_stiffness(frog.body.elasticity(), frog.surface, point.triangle);
    EXPECT_LE((k_local * d - face_force).norm(), 1e-12 * face_force.norm());

    // Its normal stiffness is (lambda + 2 mu) A / (3 h) for the face of area A at height h.
    const auto& tri = frog.surface.triangles[static_cast<size_t>(point.triangle)];
    const double area = 0.5 * triangle_area_normal(tri, frog.rest).norm();
    const double height = 3.0 * rest.volume_m3 / area;
    const Eigen::Vector3d n = frog.normal(point);
    EXPECT_NEAR(normal_stiffness_n_per_m(k_local, n), (lame.lambda_pa + 2 * lame.mu_pa) * area / (3 * height),
                1e-12 * k_local.norm());
    EXPECT_TRUE(k_local.allFinite());
    EXPECT_GT(min_eigenvalue(k_local), 0.0);

    const Eigen::Matrix3d k_c = *frog.effective.stiffness_n_per_m(frog.interpolation(point));
    std::printf(
        "  triangle %d: normal stiffness elementLocal %.4g N/m, effective %.4g N/m (ratio %.3g); "
        "frictionless %.4g vs %.4g N/m\n",
        point.triangle, normal_stiffness_n_per_m(k_local, n), normal_stiffness_n_per_m(k_c, n),
        normal_stiffness_n_per_m(k_local, n) / normal_stiffness_n_per_m(k_c, n),
        frictionless_normal_stiffness_n_per_m(k_local, n), frictionless_normal_stiffness_n_per_m(k_c, n));
  }
}

TEST(ContactSpringStiffness, ScaleBracketsTheEffectiveNormalStiffnessOverTheSurface) {
  // n^T K_c n at every surface triangle's centroid against (lambda + 2 mu) * mean edge: the claim
  // that sizes the recommended contact spring (contact_stiffness.hpp).
  FrogAtRest frog;
  const double scale = contact_stiffness_scale_n_per_m(frog.body, frog.surface);
  EXPECT_EQ(recommended_contact_spring_stiffness_n_per_m(frog.body, frog.surface, 100.0), 100.0 * scale);
  EXPECT_THROW(recommended_contact_spring_stiffness_n_per_m(frog.body, frog.surface, 0.0), ParameterError);
  const std::vector<int>& fixed = frog.body.settings().fixed_vertices;
  double lowest = std::numeric_limits<double>::infinity(), highest = 0.0, highest_away = 0.0;
  double local_lowest = std::numeric_limits<double>::infinity(), local_highest = 0.0;
  for (size_t t = 0; t < frog.surface.triangles.size(); ++t) {
    const SurfacePoint point{static_cast<int>(t), Eigen::Vector3d::Constant(1.0 / 3.0)};
    const std::optional<Eigen::Matrix3d> k_c = frog.effective.stiffness_n_per_m(frog.interpolation(point));
    if (!k_c) continue;  // held by fixed vertices only
    const Eigen::Vector3d n = frog.normal(point);
    const double ratio = normal_stiffness_n_per_m(*k_c, n) / scale;
    lowest = std::min(lowest, ratio);
    highest = std::max(highest, ratio);
    bool pinned = false;
    for (int v : frog.surface.triangles[t]) pinned = pinned || std::binary_search(fixed.begin(), fixed.end(), v);
    if (!pinned) highest_away = std::max(highest_away, ratio);
    const double local = normal_stiffness_n_per_m(
        element_local_contact_stiffness(frog.body.elasticity(), frog.surface, static_cast<int>(t)), n);
    local_lowest = std::min(local_lowest, local / (ratio * scale));
    local_highest = std::max(local_highest, local / (ratio * scale));
  }
  std::printf(
      "  scale %.4g N/m; effective normal stiffness / scale in [%.3g, %.3g] (%.3g on triangles with no "
      "fixed vertex); elementLocal / effective in [%.3g, %.3g]\n",
      scale, lowest, highest, highest_away, local_lowest, local_highest);
  EXPECT_GE(lowest, 1e-3);
  EXPECT_LE(highest, 15.0);
  EXPECT_LE(highest_away, 2.5);
}

TEST(EffectiveContactStiffness, StepMatrixServesABodyWithNothingFixed) {
  FrogAtRest frog;
  const SurfacePoint point = back_points(frog.surface, frog.rest)[0];
  const Eigen::Matrix3d k_static = *frog.effective.stiffness_n_per_m(frog.interpolation(point));

  // A_step = A_static + (PSD mass and damping terms), so K_c(step) - K_c(static) is PSD; as h
  // grows the inertia M / h^2 (~0.2 kg / h^2) vanishes next to K_c (~1e2 N/m).
  for (const double h : {1e-3, 10.0}) {
    Eigen::VectorXd diagonal;
    EffectiveContactStiffness step;
    step.factorize(newton_stiffness_system(frog.body, 1.0 / (h), diagonal));
    const Eigen::Matrix3d k_step = *step.stiffness_n_per_m(frog.interpolation(point));
    EXPECT_GE(min_eigenvalue(k_step - k_static), -1e-9 * k_static.norm());
    if (h == 10.0) {
      EXPECT_LE((k_step - k_static).norm(), 1e-4 * k_static.norm());
    } else {
      EXPECT_GT((k_step - k_static).norm(), k_static.norm());
    }
  }

  TetMesh mesh = frog.mesh;
  BodySettings settings = frog_settings(mesh);
  settings.fixed_vertices.clear();
  DeformableBody free_body(mesh, settings);
  Eigen::VectorXd force, diagonal;
  free_body.evaluate(Eigen::VectorXd::Zero(free_body.dof_count()), force, true);
  EffectiveContactStiffness stiffness;
  EXPECT_THROW(stiffness.factorize(static_contact_system(free_body.tangent(), diagonal)), SolverError);
  EXPECT_THROW(newton_stiffness_system(free_body, 1.0 / (0.0), diagonal), ParameterError);
  stiffness.factorize(newton_stiffness_system(free_body, 1.0 / (1e-3), diagonal));
  const auto k_free = stiffness.stiffness_n_per_m(contact_interpolation(
      free_body.dofs(), frog.surface.triangles[static_cast<size_t>(point.triangle)], point.barycentric));
  ASSERT_TRUE(k_free.has_value());
  EXPECT_GT(min_eigenvalue(*k_free), 0.0);
}

TEST(CholmodSolver, SetUpOnceSolveManyAgreesWithSolve) {
  FrogAtRest frog;
  Eigen::VectorXd diagonal;
  const ShiftedSystem system = newton_stiffness_system(frog.body, 1.0 / (1e-2), diagonal);
  CholmodSolver solver;
  Eigen::VectorXd x;
  EXPECT_FALSE(solver.is_set_up());
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Ones(system.rows()), x), SolverError);
  solver.setup(system);
  EXPECT_TRUE(solver.is_set_up());
  EXPECT_THROW(solver.solve(Eigen::VectorXd::Ones(3), x), SolverError);
  for (int k = 0; k < 3; ++k) {
    const Eigen::VectorXd b = Eigen::VectorXd::Random(system.rows());
    solver.solve(b, x);
    Eigen::VectorXd reference = Eigen::VectorXd::Zero(system.rows());
    CholmodSolver().solve(system, b, reference);
    EXPECT_LE((x - reference).norm(), 1e-13 * reference.norm());
    Eigen::VectorXd product(system.rows());
    system.multiply(x, product);
    EXPECT_LE((product - b).norm(), 1e-12 * b.norm());
  }
  EXPECT_EQ(solver.symbolic_analysis_count(), 1);
  // b = 0 gives x = 0 and keeps the factor.
  solver.solve(Eigen::VectorXd::Zero(system.rows()), x);
  EXPECT_TRUE(x.isZero(0.0));
  EXPECT_TRUE(solver.is_set_up());
}

TEST(ContactStiffnessModel, ParsesItsNames) {
  EXPECT_EQ(parse_contact_stiffness_model("effectiveStatic"), ContactStiffnessModel::effective_static);
  EXPECT_EQ(parse_contact_stiffness_model("elementLocal"), ContactStiffnessModel::element_local);
  EXPECT_EQ(to_string(ContactStiffnessModel::element_local), "elementLocal");
  EXPECT_THROW(parse_contact_stiffness_model("local"), ParameterError);
}

}  // namespace
}  // namespace tissue
