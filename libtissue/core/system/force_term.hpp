// ForceTerm: a force on a body's mesh vertices beside its elasticity, which the body adds to f_int
// and its tangent at every evaluate(): the god-object contact's spring (contact/point_spring.hpp).
// A term knows vertices and tangent blocks, not what it stands for; the body and the integrators
// know terms, not contact. A term the step must not damp as tissue (a rigid tool) enters the
// tangent with the share Integrator::undamped_tangent_share() gives (its force whole).
#pragma once

#include "core/system/block_sparse_matrix.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <span>

namespace tissue {

/// Where a body's mesh vertices sit in its tangent (valid until the tangent is re-laid out, when
/// the body calls ForceTerm::locate() again).
struct TermLayout {
  int vertex_count = 0;
  std::span<const int> vertex_row;  ///< per mesh vertex: its block row, -1 for a fixed vertex
  const BlockSparseMatrix* tangent = nullptr;
};

class ForceTerm {
 public:
  virtual ~ForceTerm() = default;
  /// Adds the term's part of f_int (3 per mesh vertex) at the vertex positions (3 per mesh vertex).
  virtual void add_force(const Eigen::VectorXd& positions_m, Eigen::VectorXd& vertex_forces_n) = 0;
  /// Adds the term's stiffness d f / d x to the body's tangent, at the blocks locate() found.
  virtual void add_tangent(BlockSparseMatrix& tangent) const = 0;
  /// Adds the term's blocks of the tangent (as add_tangent enters them) times `vector` (3 per block
  /// row of the layout's tangent) to `product`: the share of the tangent's product that is the term's.
  virtual void add_tangent_product(const Eigen::VectorXd& vector, Eigen::VectorXd& product) const = 0;
  /// The term's potential at the vertex positions [J].
  [[nodiscard]] virtual double energy_j(const Eigen::VectorXd& positions_m) const = 0;
  /// Finds its blocks in `layout`: when attached to a body and after the body's tangent was re-laid out.
  virtual void locate(const TermLayout& layout) = 0;
  /// Whether the term adds nothing now (no force, stiffness or energy at any positions).
  [[nodiscard]] virtual bool idle() const = 0;
  /// Moves on whenever the term's force or stiffness at the same positions may have changed (its
  /// setters call changed()): an evaluation ahead of a step is not taken after it moved.
  [[nodiscard]] std::uint64_t revision() const { return m_revision; }

 protected:
  void changed() { ++m_revision; }

 private:
  std::uint64_t m_revision = 0;
};

}  // namespace tissue
