// PointSpringTerm (see point_spring.hpp).
#include "core/contact/point_spring.hpp"

#include "core/parameter_error.hpp"

#include <cmath>
#include <string>

namespace tissue {

Eigen::Vector3d spring_material_point_m(const PointSpring& spring, const Eigen::VectorXd& positions_m) {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < 3; ++i) {
    point_m += spring.weights[static_cast<Eigen::Index>(i)] * positions_m.segment<3>(3 * spring.vertices[i]);
  }
  return point_m;
}

Eigen::Matrix3d spring_projector(const PointSpring& spring) {
  if (spring.direction.isZero(0.0)) return Eigen::Matrix3d::Identity();
  return spring.direction * spring.direction.transpose();
}

Eigen::Vector3d spring_force_on_body_n(const PointSpring& spring, const Eigen::Vector3d& material_point_m) {
  return spring.stiffness_n_per_m * (spring_projector(spring) * (spring.target_m - material_point_m)) +
         spring.constant_force_on_body_n;
}

Eigen::Vector3d springs_force_on_body_n(const std::vector<PointSpring>& springs, const Eigen::VectorXd& positions_m) {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  for (const PointSpring& spring : springs) {
    force_n += spring_force_on_body_n(spring, spring_material_point_m(spring, positions_m));
  }
  return force_n;
}

namespace {

// f_int gains (k D (x_p - target) - F) w_i on vertex i: minus the force on the body, which it returns.
Eigen::Vector3d add_spring_force(const PointSpring& spring, const Eigen::VectorXd& positions_m,
                                 Eigen::VectorXd& vertex_forces_n) {
  const Eigen::Vector3d force_on_body_n = spring_force_on_body_n(spring, spring_material_point_m(spring, positions_m));
  for (size_t i = 0; i < 3; ++i) {
    vertex_forces_n.segment<3>(3 * spring.vertices[i]) -=
        spring.weights[static_cast<Eigen::Index>(i)] * force_on_body_n;
  }
  return force_on_body_n;
}

void add_spring_tangent(const PointSpring& spring, const std::array<int, 9>& slots, BlockSparseMatrix& tangent) {
  const Eigen::Matrix3d projector = spring_projector(spring);
  for (size_t i = 0; i < 3; ++i) {
    for (size_t j = 0; j < 3; ++j) {
      const int slot = slots[3 * i + j];
      if (slot < 0) continue;  // a fixed vertex
      tangent.block(slot) +=
          (spring.tangent_fraction * spring.stiffness_n_per_m * spring.weights[static_cast<Eigen::Index>(i)] *
           spring.weights[static_cast<Eigen::Index>(j)]) *
          projector;
    }
  }
}

// The blocks add_spring_tangent enters, c k w_i w_j D, times `vector`, added to `product` by rows.
void add_spring_tangent_product(const PointSpring& spring, const std::array<int, 3>& rows,
                                const Eigen::VectorXd& vector, Eigen::VectorXd& product) {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // sum_j w_j v_j over the free vertices
  for (size_t j = 0; j < 3; ++j) {
    if (rows[j] >= 0) point += spring.weights[static_cast<Eigen::Index>(j)] * vector.segment<3>(3L * rows[j]);
  }
  const Eigen::Vector3d force =
      (spring.tangent_fraction * spring.stiffness_n_per_m) * (spring_projector(spring) * point);
  for (size_t i = 0; i < 3; ++i) {
    if (rows[i] >= 0) product.segment<3>(3L * rows[i]) += spring.weights[static_cast<Eigen::Index>(i)] * force;
  }
}

std::array<int, 3> spring_rows(const PointSpring& spring, const TermLayout& layout) {
  std::array<int, 3> rows{};
  for (size_t i = 0; i < 3; ++i) rows[i] = layout.vertex_row[static_cast<size_t>(spring.vertices[i])];
  return rows;
}

double spring_energy_j(const PointSpring& spring, const Eigen::VectorXd& positions_m) {
  // D is a projector (D^T D = D): k/2 |D (x_p - target)|^2; F's potential is -F . x_p.
  const Eigen::Vector3d point_m = spring_material_point_m(spring, positions_m);
  return 0.5 * spring.stiffness_n_per_m * (spring_projector(spring) * (point_m - spring.target_m)).squaredNorm() -
         spring.constant_force_on_body_n.dot(point_m);
}

std::array<int, 9> spring_slots(const PointSpring& spring, const TermLayout& layout) {
  std::array<int, 9> slots{};
  slots.fill(-1);
  for (size_t i = 0; i < 3; ++i) {
    for (size_t j = 0; j < 3; ++j) {
      const int row = layout.vertex_row[static_cast<size_t>(spring.vertices[i])];
      const int col = layout.vertex_row[static_cast<size_t>(spring.vertices[j])];
      if (row >= 0 && col >= 0) slots[3 * i + j] = layout.tangent->find_slot(row, col);
    }
  }
  return slots;
}

void validate_spring(const PointSpring& s, const TermLayout& layout) {
  for (const int v : s.vertices) {
    if (v < 0 || v >= layout.vertex_count) {
      throw ParameterError("point spring: vertex " + std::to_string(v) + " outside [0, " +
                           std::to_string(layout.vertex_count) + ")");
    }
  }
  if (!s.weights.allFinite() || std::abs(s.weights.sum() - 1.0) > 1e-6) {
    throw ParameterError("point spring: weights must be finite and sum to 1");
  }
  if (!s.target_m.allFinite()) throw ParameterError("point spring: target must be finite");
  if (!s.constant_force_on_body_n.allFinite()) throw ParameterError("point spring: the constant force must be finite");
  if (!s.direction.allFinite() || (!s.direction.isZero(0.0) && std::abs(s.direction.norm() - 1.0) > 1e-6)) {
    throw ParameterError("point spring: the direction must be zero or a unit vector");
  }
  if (!std::isfinite(s.stiffness_n_per_m) || s.stiffness_n_per_m < 0.0) {
    throw ParameterError("point spring: stiffness must be finite and >= 0, got " + std::to_string(s.stiffness_n_per_m));
  }
  if (!(s.tangent_fraction > 0.0 && s.tangent_fraction <= 1.0)) {
    throw ParameterError("point spring: the tangent fraction must be in (0, 1], got " +
                         std::to_string(s.tangent_fraction));
  }
  for (const int a : s.vertices) {
    for (const int b : s.vertices) {
      const int row = layout.vertex_row[static_cast<size_t>(a)];
      const int col = layout.vertex_row[static_cast<size_t>(b)];
      if (row >= 0 && col >= 0 && layout.tangent->find_slot(row, col) < 0) {
        throw ParameterError("point spring: vertices " + std::to_string(a) + " and " + std::to_string(b) +
                             " share no tet");
      }
    }
  }
}

}  // namespace

void PointSpringTerm::add_force(const Eigen::VectorXd& positions_m, Eigen::VectorXd& vertex_forces_n) {
  m_force_on_body_n.setZero();
  if (!m_spring) return;
  m_force_on_body_n = add_spring_force(*m_spring, positions_m, vertex_forces_n);
  for (const PointSpring& spring : m_pad) m_force_on_body_n += add_spring_force(spring, positions_m, vertex_forces_n);
}

void PointSpringTerm::add_tangent(BlockSparseMatrix& tangent) const {
  if (!m_spring) return;
  add_spring_tangent(*m_spring, m_slots, tangent);
  for (size_t p = 0; p < m_pad.size(); ++p) add_spring_tangent(m_pad[p], m_pad_slots[p], tangent);
}

void PointSpringTerm::add_tangent_product(const Eigen::VectorXd& vector, Eigen::VectorXd& product) const {
  if (!m_spring) return;
  add_spring_tangent_product(*m_spring, m_rows[0], vector, product);
  for (size_t p = 0; p < m_pad.size(); ++p) add_spring_tangent_product(m_pad[p], m_rows[p + 1], vector, product);
}

double PointSpringTerm::energy_j(const Eigen::VectorXd& positions_m) const {
  if (!m_spring) return 0.0;
  double energy_j = spring_energy_j(*m_spring, positions_m);
  for (const PointSpring& spring : m_pad) energy_j += spring_energy_j(spring, positions_m);
  return energy_j;
}

void PointSpringTerm::locate(const TermLayout& layout) {
  m_slots.fill(-1);
  m_pad_slots.clear();
  m_rows.clear();
  if (!m_spring) return;
  m_slots = spring_slots(*m_spring, layout);
  m_rows.push_back(spring_rows(*m_spring, layout));
  for (const PointSpring& spring : m_pad) {
    m_pad_slots.push_back(spring_slots(spring, layout));
    m_rows.push_back(spring_rows(spring, layout));
  }
}

void PointSpringTerm::set(std::optional<PointSpring> spring, const TermLayout& layout, std::vector<PointSpring> pad) {
  if (!spring && !pad.empty()) throw ParameterError("point spring: a pad's springs without the point's spring");
  if (spring) validate_spring(*spring, layout);
  for (const PointSpring& s : pad) validate_spring(s, layout);
  // No spring before or after: the force stays zero (a probe away from the body sets this every step).
  if (m_spring || spring) changed();
  m_spring = std::move(spring);
  m_pad = std::move(pad);
  m_force_on_body_n.setZero();
  locate(layout);
}

}  // namespace tissue
