// Quasi-static poke of the full co-rotational model (see quasi_static_poke.hpp).
#include "core/contact/quasi_static_poke.hpp"

#include "core/contact/contact_stiffness.hpp"

#include <Eigen/Dense>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

// v += P lambda (lambda spread over the point's free vertices by their weights).
void add_point_force(const ContactInterpolation& point, const Eigen::Vector3d& lambda, Eigen::VectorXd& v) {
  for (size_t k = 0; k < 3; ++k) {
    if (point.rows[k] >= 0) v.segment<3>(3 * point.rows[k]) += point.weights[static_cast<Eigen::Index>(k)] * lambda;
  }
}

// P^T u: the point's displacement.
Eigen::Vector3d point_displacement(const ContactInterpolation& point, const Eigen::VectorXd& u) {
  Eigen::Vector3d d = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < 3; ++k) {
    if (point.rows[k] >= 0) d += point.weights[static_cast<Eigen::Index>(k)] * u.segment<3>(3 * point.rows[k]);
  }
  return d;
}

struct BondedSolver {
  BondedSolver(DeformableBody& b, const QuasiStaticPokeSettings& s) : body(b), settings(s) {}

  DeformableBody& body;
  const QuasiStaticPokeSettings& settings;
  EffectiveContactStiffness stiffness;
  Eigen::VectorXd zero_diagonal, internal_force, residual, correction, diagonal, positions;
  int newton_iterations = 0;
  double force_residual = 0.0;
  Eigen::Matrix3d contact_stiffness = Eigen::Matrix3d::Zero();

  double largest_stiffness() {
    body.tangent().diagonal(diagonal);
    return diagonal.cwiseAbs().maxCoeff();
  }
  double largest_position() {
    body.positions(Eigen::VectorXd::Zero(body.dof_count()), positions);
    return positions.cwiseAbs().maxCoeff();
  }

  // Newton with a Lagrange multiplier for P^T u = offset (offset = target - x_s(rest)). On return
  // the tangent, its factor and contact_stiffness are those of the final u.
  bool solve(const ContactInterpolation& point, const Eigen::Vector3d& offset, Eigen::VectorXd& u,
             Eigen::Vector3d& lambda) {
    const double gap_tolerance = settings.force_tolerance * offset.norm() + 1e-15;
    for (int iteration = 0;; ++iteration) {
      body.evaluate(u, internal_force, /*update_tangent=*/true);
      residual = internal_force - body.external_force_n();
      add_point_force(point, -lambda, residual);
      const Eigen::Vector3d gap = offset - point_displacement(point, u);
      const double scale = lambda.norm() + body.external_force_n().norm();
      const double r_norm = residual.norm();
      if (!std::isfinite(r_norm)) return false;
      // f_int is computed from positions, not displacements, so its rounding is ~ eps |K| |x| per
      // unknown whatever the poke: a tiny poke is converged at that floor (10 eps for margin).
      const double floor = 1e-15 * std::sqrt(static_cast<double>(u.size())) * largest_stiffness() * largest_position();
      force_residual = r_norm == 0.0 ? 0.0 : (scale > 0.0 ? r_norm / scale : std::numeric_limits<double>::infinity());
      const bool balanced = force_residual <= settings.force_tolerance || r_norm <= floor;

      try {
        stiffness.factorize(static_contact_system(body.tangent(), zero_diagonal));
      } catch (const SolverError&) {
        return false;  // the tangent lost positive definiteness (e.g. a buckling poke)
      }
      const std::optional<Eigen::Matrix3d> k_c = stiffness.stiffness_n_per_m(point);
      if (!k_c) throw std::invalid_argument("quasi-static poke: the contact point lies on fixed vertices only");
      contact_stiffness = *k_c;
      if (balanced && gap.norm() <= gap_tolerance) return true;
      if (iteration >= settings.max_newton_iterations) return false;

      stiffness.solve(residual, correction);  // y = K^-1 r
      const Eigen::Vector3d lambda_step = contact_stiffness * (gap + point_displacement(point, correction));
      u += stiffness.unit_force_response(point) * lambda_step - correction;
      lambda += lambda_step;
      ++newton_iterations;
    }
  }
};

// Two unit vectors spanning the plane normal to n (unit).
Eigen::Matrix<double, 3, 2> tangent_basis(const Eigen::Vector3d& n) {
  Eigen::Index smallest = 0;
  n.cwiseAbs().minCoeff(&smallest);
  const Eigen::Vector3d first = n.cross(Eigen::Vector3d::Unit(smallest)).normalized();
  Eigen::Matrix<double, 3, 2> basis;
  basis.col(0) = first;
  basis.col(1) = n.cross(first);
  return basis;
}

// Detaches the body's force terms (the contact spring) for the lifetime of the guard, then
// attaches them again.
class ForceTermsDetached {
 public:
  explicit ForceTermsDetached(DeformableBody& body) : m_body(body), m_saved(body.force_terms()) {
    for (ForceTerm* term : m_saved) m_body.detach(*term);
  }
  ~ForceTermsDetached() {
    for (ForceTerm* term : m_saved) m_body.attach(*term);
  }
  ForceTermsDetached(const ForceTermsDetached&) = delete;
  ForceTermsDetached& operator=(const ForceTermsDetached&) = delete;

 private:
  DeformableBody& m_body;
  std::vector<ForceTerm*> m_saved;
};

}  // namespace

QuasiStaticPoke quasi_static_poke(DeformableBody& body, const SurfaceTriangles& triangles, const SurfacePoint& start,
                                  const Eigen::Vector3d& target_m, const QuasiStaticPokeSettings& settings,
                                  const Eigen::VectorXd& initial_displacement_m) {
  if (body.settings().fixed_vertices.empty()) {
    throw std::invalid_argument("quasi-static poke: the body has no fixed vertices, so no static equilibrium");
  }
  if (!target_m.allFinite()) throw std::invalid_argument("quasi-static poke: the target is not finite");
  if (start.triangle < 0 || start.triangle >= static_cast<int>(triangles.size())) {
    throw std::invalid_argument("quasi-static poke: start triangle " + std::to_string(start.triangle) +
                                " is not on the surface");
  }
  const int n = body.dof_count();
  if (initial_displacement_m.size() != 0 && initial_displacement_m.size() != n) {
    throw std::invalid_argument("quasi-static poke: the initial displacement has " +
                                std::to_string(initial_displacement_m.size()) + " values, the body has " +
                                std::to_string(n) + " unknowns");
  }
  const ForceTermsDetached terms_detached(body);

  VertexTriangles adjacency;
  adjacency.build(triangles, body.mesh().vertex_count());
  Eigen::VectorXd rest_positions, positions;
  body.positions(Eigen::VectorXd::Zero(n), rest_positions);

  QuasiStaticPoke result;
  Eigen::VectorXd u = initial_displacement_m.size() == n ? initial_displacement_m : Eigen::VectorXd::Zero(n);
  Eigen::Vector3d lambda = Eigen::Vector3d::Zero();
  BondedSolver bonded(body, settings);
  SurfacePoint contact = start;
  for (int slide = 0;; ++slide) {
    const std::array<int, 3>& triangle = triangles[static_cast<size_t>(contact.triangle)];
    const ContactInterpolation point = contact_interpolation(body.dofs(), triangle, contact.barycentric);
    const Eigen::Vector3d offset = target_m - surface_point_position_m(contact, triangles, rest_positions);
    const bool solved = bonded.solve(point, offset, u, lambda);

    body.positions(u, positions);
    const SurfaceProjection here = slide_to_closest_point(target_m, contact, triangles, adjacency, positions);
    const Eigen::Vector3d normal = smooth_normal(here.point, triangles, adjacency, positions);
    const Eigen::Vector3d tangential = lambda - lambda.dot(normal) * normal;
    result.tangential_residual = lambda.norm() > 0.0 ? tangential.norm() / lambda.norm() : 0.0;
    result.slide_iterations = slide;
    if (!solved) break;
    if (settings.friction == PokeFriction::bonded || result.tangential_residual <= settings.tangential_tolerance) {
      result.converged = true;
      break;
    }
    if (slide >= settings.max_slide_iterations) break;

    // Shift the held point by delta in the tangent plane: the tangential reaction changes by
    // -T^T K_c delta, which cancels it to first order.
    const Eigen::Matrix<double, 3, 2> basis = tangent_basis(normal);
    const Eigen::Matrix2d tangential_stiffness = basis.transpose() * bonded.contact_stiffness * basis;
    const Eigen::Vector3d delta = basis * tangential_stiffness.ldlt().solve(basis.transpose() * lambda);
    const SurfaceProjection next = slide_to_closest_point(target_m + delta, contact, triangles, adjacency, positions);
    if (next.point.triangle == contact.triangle && (next.point.barycentric - contact.barycentric).norm() <= 1e-15) {
      // Held on an edge or a vertex: the reaction lies in the feature's normal cone; no slide moves it.
      result.converged = true;
      break;
    }
    contact = next.point;
  }

  result.force_on_tool_n = -lambda;
  result.contact = contact;
  body.positions(u, positions);
  result.normal = smooth_normal(slide_to_closest_point(target_m, contact, triangles, adjacency, positions).point,
                                triangles, adjacency, positions);
  result.displacement_m = std::move(u);
  result.contact_stiffness_n_per_m = bonded.contact_stiffness;
  result.force_residual = bonded.force_residual;
  result.newton_iterations = bonded.newton_iterations;
  return result;
}

}  // namespace tissue
