// Co-rotational forces and tangent, written in the rotated-gradient form: with c_i = R g_i,
//   R K_ij R^T = V [lambda c_i c_j^T + mu c_j c_i^T + mu (g_i . g_j) I],
// which costs ~20 flops per block instead of the 54 of R K_ij R^T (Vega spends three quarters of
// a step rebuilding the rotated stiffness; this is where we win it back).
#include "core/fem/corotational.hpp"

#include "core/fem/corotational_kernel.hpp"

#include <cassert>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

TetPositions gather(const Eigen::VectorXd& positions_m, const Tet& tet) {
  TetPositions x;
  for (int i = 0; i < 4; ++i) x[static_cast<size_t>(i)] = positions_m.segment<3>(3 * tet[static_cast<size_t>(i)]);
  return x;
}

}  // namespace

CorotationalElasticity::CorotationalElasticity(const TetMesh& mesh, const Material& material,
                                               const RotationSettings& rotation)
    : m_tets(mesh.tets),
      m_lame((validate(material), lame_parameters(material))),
      m_rotation_settings((validate(rotation), rotation)) {
  m_rest.reserve(m_tets.size());
  for (const Tet& tet : m_tets) {
    TetPositions rest_positions;
    for (int i = 0; i < 4; ++i) {
      rest_positions[static_cast<size_t>(i)] = mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(i)])];
    }
    m_rest.push_back(precompute_tet(rest_positions));
  }
  m_rotations.assign(m_tets.size(), Eigen::Matrix3d::Identity());
  m_warm_starts.assign(m_tets.size(), Eigen::Quaterniond::Identity());
  m_excluded.assign(m_tets.size(), 0);
}

void CorotationalElasticity::exclude(int tet) {
  if (tet < 0 || tet >= tet_count()) {
    throw ParameterError("CorotationalElasticity::exclude: tet " + std::to_string(tet) + " outside [0, " +
                         std::to_string(tet_count()) + ")");
  }
  m_excluded[static_cast<size_t>(tet)] = 1;
}

void CorotationalElasticity::restore_rotations(const std::vector<Eigen::Matrix3d>& rotations,
                                               const std::vector<Eigen::Quaterniond>& warm_starts) {
  if (rotations.size() != m_tets.size() || warm_starts.size() != m_tets.size()) {
    throw std::invalid_argument("co-rotational elasticity: expected one rotation and warm start per tet (" +
                                std::to_string(m_tets.size()) + "), got " + std::to_string(rotations.size()) +
                                " and " + std::to_string(warm_starts.size()));
  }
  m_rotations = rotations;
  m_warm_starts = warm_starts;
}

void CorotationalElasticity::reset_rotations() {
  std::fill(m_rotations.begin(), m_rotations.end(), Eigen::Matrix3d::Identity());
  std::fill(m_warm_starts.begin(), m_warm_starts.end(), Eigen::Quaterniond::Identity());
}

void CorotationalElasticity::evaluate(const Eigen::VectorXd& positions_m, Eigen::VectorXd& internal_forces_n,
                                      BlockSparseMatrix* tangent, const std::vector<TetSlots>* slots) {
  assert(tangent == nullptr || (slots != nullptr && slots->size() == m_tets.size()));
  // Tets go in batches of ROTATION_BATCH: their rotations are extracted side by side (SIMD lanes),
  // then each tet's force and tangent blocks are added in turn.
  std::array<size_t, ROTATION_BATCH> batch{};
  std::array<Eigen::Matrix3d, ROTATION_BATCH> gradients;
  std::array<Eigen::Quaterniond*, ROTATION_BATCH> warm_starts{};
  std::array<Eigen::Matrix3d*, ROTATION_BATCH> rotations{};
  size_t next = 0;
  while (next < m_tets.size()) {
    int count = 0;
    for (; next < m_tets.size() && count < ROTATION_BATCH; ++next) {
      if (m_excluded[next] != 0) continue;
      const auto lane = static_cast<size_t>(count++);
      batch[lane] = next;
      gradients[lane] = deformation_gradient(m_rest[next], gather(positions_m, m_tets[next]));
      warm_starts[lane] = &m_warm_starts[next];
      rotations[lane] = &m_rotations[next];
    }
    extract_rotations(count, gradients.data(), warm_starts.data(), rotations.data(), m_rotation_settings);
    for (int lane = 0; lane < count; ++lane) {
      add_tet(batch[static_cast<size_t>(lane)], gradients[static_cast<size_t>(lane)], internal_forces_n, tangent, slots);
    }
  }
}

void CorotationalElasticity::add_tet(size_t t, const Eigen::Matrix3d& f, Eigen::VectorXd& internal_forces_n,
                                     BlockSparseMatrix* tangent, const std::vector<TetSlots>* slots) const {
  const Tet& tet = m_tets[t];
  const TetRest& rest = m_rest[t];
  const Eigen::Matrix3d& r = m_rotations[t];

  // f_i = V R sigma g_i (equal to R K_e (R^T x - X), see DESIGN section 4).
  const Eigen::Matrix<double, 3, 4> forces = corotated_forces(rest, r, f, m_lame);
  for (int i = 0; i < 4; ++i) internal_forces_n.segment<3>(3 * tet[static_cast<size_t>(i)]) += forces.col(i);

  if (tangent == nullptr) return;
  const Eigen::Matrix<double, 3, 4> c = r * rest.shape_gradients_per_m;  // rotated shape gradients
  const TetSlots& tet_slots = (*slots)[t];
  for (int i = 0; i < 4; ++i) {
    for (int j = i; j < 4; ++j) {
      const int slot_ij = tet_slots[static_cast<size_t>(4 * i + j)];
      if (slot_ij < 0) continue;
      const Eigen::Matrix3d block = rotated_stiffness_block(rest, m_lame, c, i, j);
      tangent->block(slot_ij) += block;
      if (i != j) tangent->block(tet_slots[static_cast<size_t>(4 * j + i)]) += block.transpose();
    }
  }
}

double CorotationalElasticity::elastic_energy_j(const Eigen::VectorXd& positions_m) const {
  double energy = 0.0;
  for (size_t t = 0; t < m_tets.size(); ++t) {
    if (m_excluded[t] != 0) continue;
    const Eigen::Matrix3d f = deformation_gradient(m_rest[t], gather(positions_m, m_tets[t]));
    Eigen::Quaterniond warm_start = m_warm_starts[t];  // a copy: reporting must not change the dynamics
    energy += corotated_energy_j(m_rest[t], extract_rotation(f, warm_start, m_rotation_settings), f, m_lame);
  }
  return energy;
}

std::vector<double> lumped_vertex_masses(const TetMesh& mesh, double density_kg_per_m3) {
  std::vector<double> masses(static_cast<size_t>(mesh.vertex_count()), 0.0);
  for (const Tet& tet : mesh.tets) {
    const auto& p = mesh.rest_positions_m;
    const double quarter_mass = 0.25 * density_kg_per_m3 *
                                signed_tet_volume(p[static_cast<size_t>(tet[0])], p[static_cast<size_t>(tet[1])],
                                                  p[static_cast<size_t>(tet[2])], p[static_cast<size_t>(tet[3])]);
    for (int v : tet) masses[static_cast<size_t>(v)] += quarter_mass;
  }
  return masses;
}

}  // namespace tissue
