// DeformableBody: a tet mesh made into a DynamicsModel: co-rotational elasticity, lumped mass,
// Rayleigh damping, gravity and fixed vertices (removed from the unknowns).
#pragma once

#include "core/fem/corotational.hpp"
#include "core/fem/material.hpp"
#include "core/mesh/tet_mesh.hpp"
#include "core/system/assembly.hpp"
#include "core/system/block_sparse_matrix.hpp"
#include "core/system/dynamics_model.hpp"

#include <Eigen/Core>

#include <vector>

namespace tissue {

struct BodySettings {
  Material material;
  RayleighDamping damping;
  Eigen::Vector3d gravity_m_per_s2{0.0, -9.81, 0.0};
  std::vector<int> fixed_vertices;  ///< 0-based; they keep their rest positions
  BlockSparseMatrix::Reserve reserve;
};

class DeformableBody final : public DynamicsModel {
 public:
  /// Throws ParameterError for invalid settings (material, damping, non-finite gravity,
  /// fixed vertex ids out of range).
  DeformableBody(TetMesh mesh, BodySettings settings);

  [[nodiscard]] int dof_count() const override { return 3 * m_dofs.free_vertex_count(); }
  [[nodiscard]] const Eigen::VectorXd& mass_kg() const override { return m_mass_kg; }
  [[nodiscard]] const RayleighDamping& damping() const override { return m_settings.damping; }
  [[nodiscard]] const Eigen::VectorXd& external_force_n() const override { return m_external_force_n; }
  void evaluate(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n, bool update_tangent) override;
  [[nodiscard]] const BlockSparseMatrix& tangent() const override { return m_tangent; }

  [[nodiscard]] const TetMesh& mesh() const { return m_mesh; }
  [[nodiscard]] const DofMap& dofs() const { return m_dofs; }
  [[nodiscard]] const BodySettings& settings() const { return m_settings; }
  [[nodiscard]] const CorotationalElasticity& elasticity() const { return m_elasticity; }
  [[nodiscard]] const std::vector<double>& vertex_masses_kg() const { return m_vertex_mass_kg; }
  [[nodiscard]] double total_mass_kg() const;

  /// Current positions of all vertices (3 per vertex) for a displacement of the unknowns.
  void positions(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& positions_m) const;
  /// Elastic energy at displacement u. [J]
  [[nodiscard]] double elastic_energy_j(const Eigen::VectorXd& displacement_m);
  /// 1/2 v^T M v. [J]
  [[nodiscard]] double kinetic_energy_j(const Eigen::VectorXd& velocity_m_per_s) const;

 private:
  TetMesh m_mesh;
  BodySettings m_settings;
  DofMap m_dofs;
  CorotationalElasticity m_elasticity;
  std::vector<double> m_vertex_mass_kg;
  Eigen::VectorXd m_mass_kg;
  Eigen::VectorXd m_external_force_n;
  BlockSparseMatrix m_tangent;
  std::vector<TetSlots> m_slots;
  Eigen::VectorXd m_positions_m;      // all vertices
  Eigen::VectorXd m_vertex_forces_n;  // all vertices
};

}  // namespace tissue
