// DeformableBody: scatter the unknowns to vertex positions, evaluate the FEM, gather forces back.
#include "core/fem/deformable_body.hpp"

#include <algorithm>
#include <string>

namespace tissue {
namespace {

BodySettings checked(BodySettings settings, int vertex_count) {
  validate(settings.material);
  validate(settings.damping);
  if (!settings.gravity_m_per_s2.allFinite()) throw ParameterError("gravity must be finite");
  for (int v : settings.fixed_vertices) {
    if (v < 0 || v >= vertex_count) {
      throw ParameterError("fixed vertex " + std::to_string(v) + " is outside [0, " + std::to_string(vertex_count) +
                           ")");
    }
  }
  std::sort(settings.fixed_vertices.begin(), settings.fixed_vertices.end());
  settings.fixed_vertices.erase(std::unique(settings.fixed_vertices.begin(), settings.fixed_vertices.end()),
                                settings.fixed_vertices.end());
  return settings;
}

}  // namespace

DeformableBody::DeformableBody(TetMesh mesh, BodySettings settings)
    : m_mesh(std::move(mesh)),
      m_settings(checked(std::move(settings), m_mesh.vertex_count())),
      m_dofs(make_dof_map(m_mesh.vertex_count(), m_settings.fixed_vertices)),
      m_elasticity(m_mesh, m_settings.material),
      m_vertex_mass_kg(lumped_vertex_masses(m_mesh, m_settings.material.density_kg_per_m3)),
      m_tangent(stiffness_pattern(m_mesh, m_dofs), m_settings.reserve),
      m_slots(make_tet_slots(m_mesh, m_dofs, m_tangent)) {
  const int rows = m_dofs.free_vertex_count();
  m_mass_kg.resize(3 * rows);
  m_external_force_n.resize(3 * rows);
  for (int row = 0; row < rows; ++row) {
    const double mass = m_vertex_mass_kg[static_cast<size_t>(m_dofs.row_vertex[static_cast<size_t>(row)])];
    m_mass_kg.segment<3>(3 * row).setConstant(mass);
    m_external_force_n.segment<3>(3 * row) = mass * m_settings.gravity_m_per_s2;
  }
  m_positions_m.resize(3 * m_mesh.vertex_count());
  m_vertex_forces_n.resize(3 * m_mesh.vertex_count());
  positions(Eigen::VectorXd::Zero(dof_count()), m_positions_m);
}

double DeformableBody::total_mass_kg() const {
  double total = 0.0;
  for (double m : m_vertex_mass_kg) total += m;
  return total;
}

void DeformableBody::positions(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& positions_m) const {
  positions_m.resize(3 * m_mesh.vertex_count());
  for (int v = 0; v < m_mesh.vertex_count(); ++v) {
    const int row = m_dofs.vertex_row[static_cast<size_t>(v)];
    positions_m.segment<3>(3 * v) = m_mesh.rest_positions_m[static_cast<size_t>(v)];
    if (row >= 0) positions_m.segment<3>(3 * v) += displacement_m.segment<3>(3 * row);
  }
}

void DeformableBody::evaluate(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n,
                              bool update_tangent) {
  positions(displacement_m, m_positions_m);
  m_vertex_forces_n.setZero();
  if (update_tangent) m_tangent.set_zero();
  m_elasticity.evaluate(m_positions_m, m_vertex_forces_n, update_tangent ? &m_tangent : nullptr, &m_slots);
  internal_force_n.resize(dof_count());
  for (int row = 0; row < m_dofs.free_vertex_count(); ++row) {
    internal_force_n.segment<3>(3 * row) =
        m_vertex_forces_n.segment<3>(3 * m_dofs.row_vertex[static_cast<size_t>(row)]);
  }
}

double DeformableBody::elastic_energy_j(const Eigen::VectorXd& displacement_m) {
  positions(displacement_m, m_positions_m);
  return m_elasticity.elastic_energy_j(m_positions_m);
}

double DeformableBody::kinetic_energy_j(const Eigen::VectorXd& velocity_m_per_s) const {
  return 0.5 * velocity_m_per_s.dot(m_mass_kg.cwiseProduct(velocity_m_per_s));
}

}  // namespace tissue
