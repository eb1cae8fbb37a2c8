// Contact stiffness models (see contact_stiffness.hpp).
#include "core/contact/contact_stiffness.hpp"

#include "core/material/material.hpp"
#include "core/solve/cholmod_factor.hpp"
#include "core/fem/tet_element.hpp"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>
#include <string>

namespace tissue {

ContactStiffnessModel parse_contact_stiffness_model(std::string_view name) {
  return CONTACT_STIFFNESS_MODEL_NAMES.parse(name);
}

std::string_view to_string(ContactStiffnessModel model) { return CONTACT_STIFFNESS_MODEL_NAMES.name(model); }

ContactInterpolation contact_interpolation(const DofMap& dofs, const std::array<int, 3>& vertices,
                                           const Eigen::Vector3d& weights) {
  ContactInterpolation point;
  point.weights = weights;
  for (size_t k = 0; k < 3; ++k) {
    const int v = vertices[k];
    if (v < 0 || v >= static_cast<int>(dofs.vertex_row.size())) {
      throw std::invalid_argument("contact interpolation: vertex " + std::to_string(v) + " outside [0, " +
                                  std::to_string(dofs.vertex_row.size()) + ")");
    }
    point.rows[k] = dofs.vertex_row[static_cast<size_t>(v)];
  }
  return point;
}

ShiftedSystem static_contact_system(const BlockSparseMatrix& tangent, Eigen::VectorXd& diagonal) {
  diagonal.setZero(tangent.rows());
  return ShiftedSystem{&tangent, 1.0, &diagonal};
}

// The forward solves' output, kept between calls (no allocation once sized).
struct LowerSolutionBuffer {
  CholmodFactor::LowerSolution solution;
};

EffectiveContactStiffness::EffectiveContactStiffness()
    // K_c needs forward solves only (lower_solve: this project's loops, no BLAS). Full solves, rare
    // (unit_force_response, solve), use a simplicial copy made when first asked: they may run in a
    // worker beside the step's own CHOLMOD calls (cholmod_factor.hpp).
    : m_factor(std::make_unique<CholmodFactor>(CholmodFactor::Solves::without_blas_on_demand,
                                               CholmodFactor::Layout::quickest_factorization)),
      m_lower(std::make_unique<LowerSolutionBuffer>()) {}

EffectiveContactStiffness::~EffectiveContactStiffness() = default;

void EffectiveContactStiffness::factorize(const ShiftedSystem& system) {
  load(system);
  factorize_loaded();
}

void EffectiveContactStiffness::load(const ShiftedSystem& system) {
  m_loaded = false;
  system.check("effective contact stiffness");
  m_factor->load(system);  // drops the factor
  m_loaded = true;
}

void EffectiveContactStiffness::factorize_loaded() {
  if (!m_loaded) throw SolverError("effective contact stiffness: nothing loaded to factorize");
  if (m_factor->factorize() != CholmodFactor::Status::ok) {
    throw SolverError(m_factor->failure_message("effective contact stiffness"));
  }
}

int EffectiveContactStiffness::rows() const {
  return m_loaded && m_factor->factored() ? static_cast<int>(m_factor->rows()) : 0;
}

void EffectiveContactStiffness::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  const int n = rows();
  if (n == 0 || b.size() != n) {
    throw SolverError("effective contact stiffness: solve without a factor or with the wrong length");
  }
  x.resize(n);
  m_factor->solve(std::span<const double>(b.data(), static_cast<size_t>(n)),
                  std::span<double>(x.data(), static_cast<size_t>(n)));
}

bool EffectiveContactStiffness::check(const ContactInterpolation& point) const {
  const int n = rows();
  if (n == 0) {
    throw SolverError("effective contact stiffness: no factorized matrix (call factorize())");
  }
  bool moves = false;
  for (size_t k = 0; k < 3; ++k) {
    const int row = point.rows[k];
    if (row < -1 || 3 * row + 2 >= n) {
      throw std::invalid_argument("effective contact stiffness: block row " + std::to_string(row) +
                                  " outside the factorized matrix of " + std::to_string(n) + " rows");
    }
    moves = moves || (row >= 0 && point.weights[static_cast<Eigen::Index>(k)] != 0.0);
  }
  return moves;
}

const EffectiveContactStiffness::ResponseMatrix& EffectiveContactStiffness::unit_force_response(
    const ContactInterpolation& point) {
  // Column a of P holds w_k at scalar row 3 row_k + a; A Z = P column by column.
  (void)check(point);
  const int n = rows();
  m_response.resize(n, 3);
  m_column.setZero(n);
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t k = 0; k < 3; ++k) {
      if (point.rows[k] >= 0) m_column[3 * point.rows[k] + axis] += point.weights[static_cast<Eigen::Index>(k)];
    }
    solve(m_column, m_solution);
    m_response.col(axis) = m_solution;
    m_column.setZero();
  }
  return m_response;
}

Eigen::MatrixXd EffectiveContactStiffness::gram_of_columns() {
  m_factor->lower_solve(m_columns, m_lower->solution);
  const Eigen::MatrixXd& y = m_lower->solution.values;
  return y.transpose() * y;
}

Eigen::MatrixXd EffectiveContactStiffness::directed_gram(const DirectedSprings& first, const DirectedSprings& second) {
  m_columns.resize(first.points.size() + second.points.size());
  size_t c = 0;
  for (const DirectedSprings* springs : {&first, &second}) {
    for (const ContactInterpolation& point : springs->points) {
      (void)check(point);
      auto& column = m_columns[c++];
      column.clear();
      for (size_t k = 0; k < 3; ++k) {
        if (point.rows[k] < 0) continue;
        for (int axis = 0; axis < 3; ++axis) {
          column.emplace_back(3 * point.rows[k] + axis,
                              point.weights[static_cast<Eigen::Index>(k)] * springs->direction[axis]);
        }
      }
    }
  }
  return gram_of_columns();
}

double EffectiveContactStiffness::pad_stiffness_n_per_m(const DirectedSprings& tool, const DirectedSprings& in_matrix) {
  for (const DirectedSprings* springs : {&tool, &in_matrix}) {
    if (springs->points.size() != springs->stiffness_n_per_m.size()) {
      throw std::invalid_argument("pad contact stiffness: as many springs as points");
    }
    for (const double k : springs->stiffness_n_per_m) {
      if (!(k >= 0.0) || !std::isfinite(k)) {
        throw std::invalid_argument("pad contact stiffness: the springs' stiffness must be finite and >= 0");
      }
    }
  }
  // The factorized matrix is A'' = A + V C V^T (V: in_matrix's columns); the tool meets A + U K U^T.
  // With W = [U V] and D = diag(K, -C): A + U K U^T = A'' + W D W^T, so (Woodbury)
  //   W^T (A + U K U^T)^-1 W = G (I + D G)^-1,   G = W^T A''^-1 W,
  // whose first block is S = U^T (A + U K U^T)^-1 U; the force per unit motion along d is
  // sum k - (K 1)^T S (K 1) (each spring stretched by the motion less its point's).
  const auto n = static_cast<Eigen::Index>(tool.points.size());
  const auto m = static_cast<Eigen::Index>(in_matrix.points.size());
  const Eigen::MatrixXd g = directed_gram(tool, in_matrix);
  Eigen::VectorXd d(n + m);
  for (Eigen::Index j = 0; j < n; ++j) d[j] = tool.stiffness_n_per_m[static_cast<size_t>(j)];
  for (Eigen::Index j = 0; j < m; ++j) d[n + j] = -in_matrix.stiffness_n_per_m[static_cast<size_t>(j)];
  const Eigen::MatrixXd system = Eigen::MatrixXd::Identity(n + m, n + m) + d.asDiagonal() * g;
  // S (K 1) = first block of G (I + D G)^-1 [K 1; 0], i.e. G y with (I + D G) y = [K 1; 0].
  Eigen::VectorXd right(n + m);
  right.head(n) = d.head(n);
  right.tail(m).setZero();
  const Eigen::VectorXd y = system.partialPivLu().solve(right);
  const Eigen::VectorXd s_k1 = (g * y).head(n);
  return d.head(n).sum() - d.head(n).dot(s_k1);
}

Eigen::MatrixXd EffectiveContactStiffness::gram(std::span<const ContactInterpolation> points) {
  m_columns.resize(3 * points.size());
  for (size_t p = 0; p < points.size(); ++p) {
    for (int axis = 0; axis < 3; ++axis) {
      auto& column = m_columns[3 * p + static_cast<size_t>(axis)];
      column.clear();
      for (size_t k = 0; k < 3; ++k) {
        if (points[p].rows[k] >= 0) {
          column.emplace_back(3 * points[p].rows[k] + axis, points[p].weights[static_cast<Eigen::Index>(k)]);
        }
      }
    }
  }
  return gram_of_columns();
}

namespace {

Eigen::Matrix3d symmetric_inverse(const Eigen::Matrix3d& m) {
  const Eigen::Matrix3d inverse = (0.5 * (m + m.transpose())).inverse();
  return 0.5 * (inverse + inverse.transpose());  // symmetric up to the solves' rounding
}

}  // namespace

std::optional<Eigen::Matrix3d> EffectiveContactStiffness::stiffness_n_per_m(const ContactInterpolation& point) {
  if (!check(point)) return std::nullopt;
  const Eigen::Matrix3d compliance = gram(std::span<const ContactInterpolation>(&point, 1));  // P^T A^-1 P
  return symmetric_inverse(compliance);
}

std::optional<Eigen::Matrix3d> EffectiveContactStiffness::stiffness_n_per_m(const ContactInterpolation& point,
                                                                            const ContactInterpolation& spring_point,
                                                                            double spring_stiffness_n_per_m,
                                                                            const Eigen::Vector3d& spring_direction) {
  if (!(spring_stiffness_n_per_m >= 0.0) || !std::isfinite(spring_stiffness_n_per_m)) {
    throw std::invalid_argument("effective contact stiffness: the spring stiffness must be finite and >= 0");
  }
  if (!check(point)) return std::nullopt;
  if (spring_stiffness_n_per_m == 0.0 || !check(spring_point)) return stiffness_n_per_m(point);
  // The factor is of A' = A + k U U^T (U interpolates the spring's point). Woodbury:
  //   A^-1 = A'^-1 + A'^-1 U M^-1 U^T A'^-1,   M = I/k - U^T A'^-1 U,
  // so P^T A^-1 P = P^T A'^-1 P + (P^T A'^-1 U) M^-1 (P^T A'^-1 U)^T, all blocks of one Gram matrix.
  // M ~ K_u / k^2 is formed with a cancellation of ~log10(k / K_u) digits, harmless for k up to
  // ~1e6 K_u.
  const std::array<ContactInterpolation, 2> points{point, spring_point};
  const Eigen::MatrixXd g = gram(points);
  const Eigen::Matrix3d cross = g.topRightCorner<3, 3>();  // P^T A'^-1 U
  if (!spring_direction.isZero(0.0)) {
    // A spring along d alone: A' = A + k (U d)(U d)^T, the same with the 1 x 1 M = 1/k - d^T U^T A'^-1 U d.
    const Eigen::Vector3d cross_d = cross * spring_direction;
    const double m = 1.0 / spring_stiffness_n_per_m - spring_direction.dot(g.bottomRightCorner<3, 3>() * spring_direction);
    return symmetric_inverse(g.topLeftCorner<3, 3>() + cross_d * cross_d.transpose() / m);
  }
  Eigen::Matrix3d m = -g.bottomRightCorner<3, 3>();  // -U^T A'^-1 U
  m.diagonal().array() += 1.0 / spring_stiffness_n_per_m;
  const Eigen::Matrix3d compliance = g.topLeftCorner<3, 3>() + cross * symmetric_inverse(m) * cross.transpose();
  return symmetric_inverse(compliance);
}

Eigen::Matrix3d element_local_contact_stiffness(const CorotationalElasticity& elasticity, int tet,
                                                int opposite_local_vertex) {
  if (tet < 0 || tet >= elasticity.tet_count()) {
    throw std::invalid_argument("elementLocal contact stiffness: tet " + std::to_string(tet) + " outside [0, " +
                                std::to_string(elasticity.tet_count()) + ")");
  }
  if (opposite_local_vertex < 0 || opposite_local_vertex > 3) {
    throw std::invalid_argument("elementLocal contact stiffness: local vertex must be 0..3, got " +
                                std::to_string(opposite_local_vertex));
  }
  const Eigen::Matrix3d& rotation = elasticity.rotation(tet);
  const Eigen::Matrix3d block =
      linear_stiffness_block(elasticity.rest(tet), elasticity.lame_of(elasticity.rest(tet)), opposite_local_vertex,
                             opposite_local_vertex);
  return rotation * block * rotation.transpose();
}

Eigen::Matrix3d element_local_contact_stiffness(const CorotationalElasticity& elasticity, const SurfaceMesh& surface,
                                                int triangle) {
  if (triangle < 0 || triangle >= static_cast<int>(surface.triangle_tet.size())) {
    throw std::invalid_argument("elementLocal contact stiffness: triangle " + std::to_string(triangle) +
                                " is not a surface triangle");
  }
  return element_local_contact_stiffness(elasticity, surface.triangle_tet[static_cast<size_t>(triangle)],
                                         surface.triangle_local_face[static_cast<size_t>(triangle)]);
}

double normal_stiffness_n_per_m(const Eigen::Matrix3d& stiffness, const Eigen::Vector3d& unit_normal) {
  return unit_normal.dot(stiffness * unit_normal);
}

double frictionless_normal_stiffness_n_per_m(const Eigen::Matrix3d& stiffness, const Eigen::Vector3d& unit_normal) {
  return 1.0 / unit_normal.dot(stiffness.ldlt().solve(unit_normal));
}

Eigen::Matrix3d sliding_contact_stiffness_n_per_m(const Eigen::Matrix3d& bonded, const Eigen::Vector3d& unit_normal) {
  double normal_n_per_m = frictionless_normal_stiffness_n_per_m(bonded, unit_normal);
  if (!(normal_n_per_m > 0.0) || !std::isfinite(normal_n_per_m)) {
    normal_n_per_m = std::max(normal_stiffness_n_per_m(bonded, unit_normal), 0.0);
  }
  return normal_n_per_m * (unit_normal * unit_normal.transpose());
}

double recommended_contact_spring_stiffness_n_per_m(const DeformableBody& body, const SurfaceMesh& surface,
                                                    double factor) {
  if (!(factor > 0.0) || !std::isfinite(factor)) {
    throw ParameterError("contact spring factor must be finite and > 0, got " + std::to_string(factor));
  }
  return factor * contact_stiffness_scale_n_per_m(body, surface);
}

double mean_surface_edge_m(const DeformableBody& body, const SurfaceMesh& surface) {
  const TetMesh& mesh = body.mesh();
  double length_sum = 0.0;
  for (const auto& t : surface.triangles) {
    for (size_t k = 0; k < 3; ++k) {
      length_sum += (mesh.rest_positions_m[static_cast<size_t>(t[k])] -
                     mesh.rest_positions_m[static_cast<size_t>(t[(k + 1) % 3])])
                        .norm();
    }
  }
  return surface.triangles.empty() ? 0.0 : length_sum / (3.0 * static_cast<double>(surface.triangles.size()));
}

double contact_stiffness_scale_n_per_m(const DeformableBody& body, const SurfaceMesh& surface) {
  // With regions, the stiffest material on the surface (P-wave modulus lambda + 2 mu): a probe must
  // not sink into the stiffest part it can touch.
  const CorotationalElasticity& elasticity = body.elasticity();
  double modulus_pa = 0.0;
  for (const int tet : surface.triangle_tet) {
    const LameParameters& lame = elasticity.lame_of(elasticity.rest(tet));
    modulus_pa = std::max(modulus_pa, lame.lambda_pa + 2.0 * lame.mu_pa);
  }
  return modulus_pa * mean_surface_edge_m(body, surface);
}

ContactStiffnessRequest contact_stiffness_request(const ShiftedSystem& system, const DofMap& dofs,
                                                  const ContactInterpolation& point,
                                                  const std::optional<PointSpring>& spring,
                                                  double rigid_support_n_per_m, double floor_n_per_m,
                                                  const std::vector<PointSpring>* pad) {
  ContactStiffnessRequest request;
  request.point = point;
  if (spring) {
    request.spring_point = contact_interpolation(dofs, spring->vertices, spring->weights);
    request.spring_in_matrix_n_per_m = system.stiffness_scale * spring->tangent_fraction * spring->stiffness_n_per_m;
    request.spring_direction = spring->direction;
  }
  request.rigid_support_n_per_m = rigid_support_n_per_m;
  request.floor_n_per_m = floor_n_per_m;
  if (pad != nullptr) {
    if (!spring) throw std::invalid_argument("contact stiffness request: a pad without its centre's spring");
    request.pad.direction = spring->direction;
    request.pad_in_matrix.direction = spring->direction;
    const double in_matrix = system.stiffness_scale * spring->tangent_fraction;
    auto add = [&](const PointSpring& s) {
      const ContactInterpolation at = contact_interpolation(dofs, s.vertices, s.weights);
      request.pad.points.push_back(at);
      request.pad.stiffness_n_per_m.push_back(s.stiffness_n_per_m);
      request.pad_in_matrix.points.push_back(at);
      request.pad_in_matrix.stiffness_n_per_m.push_back(in_matrix * s.stiffness_n_per_m);
    };
    add(*spring);
    for (const PointSpring& s : *pad) add(s);
  }
  return request;
}

std::optional<Eigen::Matrix3d> condense_factored(EffectiveContactStiffness& effective,
                                                 const ContactStiffnessRequest& request) {
  try {
    if (!request.pad.points.empty()) {
      const double pad_n_per_m = effective.pad_stiffness_n_per_m(request.pad, request.pad_in_matrix);
      if (!std::isfinite(pad_n_per_m) || !(pad_n_per_m > request.floor_n_per_m)) return std::nullopt;
      return Eigen::Matrix3d(pad_n_per_m * request.pad.direction * request.pad.direction.transpose());
    }
    const std::optional<Eigen::Matrix3d> stiffness =
        request.spring_point
            ? effective.stiffness_n_per_m(request.point, *request.spring_point, request.spring_in_matrix_n_per_m,
                                          request.spring_direction)
            : effective.stiffness_n_per_m(request.point);
    if (!stiffness) return Eigen::Matrix3d::Identity() * request.rigid_support_n_per_m;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(*stiffness, Eigen::EigenvaluesOnly);
    if (!stiffness->allFinite() || !(eigen.eigenvalues().minCoeff() > request.floor_n_per_m)) return std::nullopt;
    return stiffness;
  } catch (const SolverError&) {
    return std::nullopt;
  }
}

std::optional<Eigen::Matrix3d> condense_loaded(EffectiveContactStiffness& effective,
                                               const ContactStiffnessRequest& request) {
  try {
    effective.factorize_loaded();
  } catch (const SolverError&) {
    return std::nullopt;
  }
  return condense_factored(effective, request);
}

std::optional<Eigen::Matrix3d> condensed_contact_stiffness(EffectiveContactStiffness& effective,
                                                          const ShiftedSystem& system,
                                                          const ContactStiffnessRequest& request) {
  try {
    effective.load(system);
  } catch (const SolverError&) {
    return std::nullopt;
  }
  return condense_loaded(effective, request);
}

std::optional<Eigen::Matrix3d> condensed_contact_stiffness(EffectiveContactStiffness& effective,
                                                          const ShiftedSystem& system, const DofMap& dofs,
                                                          const ContactInterpolation& point,
                                                          const std::optional<PointSpring>& spring,
                                                          double rigid_support_n_per_m, double floor_n_per_m) {
  return condensed_contact_stiffness(
      effective, system, contact_stiffness_request(system, dofs, point, spring, rigid_support_n_per_m, floor_n_per_m));
}

}  // namespace tissue
