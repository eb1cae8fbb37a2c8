// Co-rotational forces and tangent, written in the rotated-gradient form: with c_i = R g_i,
//   R K_ij R^T = V [lambda c_i c_j^T + mu c_j c_i^T + mu (g_i . g_j) I],
// which costs ~20 flops per block instead of the 54 of R K_ij R^T (Vega spends three quarters of
// a step rebuilding the rotated stiffness; this is where we win it back).
#include "core/fem/corotational.hpp"

#include <cassert>

namespace tissue {
namespace {

TetPositions gather(const Eigen::VectorXd& positions_m, const Tet& tet) {
  TetPositions x;
  for (int i = 0; i < 4; ++i) x[static_cast<size_t>(i)] = positions_m.segment<3>(3 * tet[static_cast<size_t>(i)]);
  return x;
}

// The rotated-back (co-rotational) strain eps = sym(R^T F) - I.
Eigen::Matrix3d corotated_strain(const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& f) {
  const Eigen::Matrix3d s = rotation.transpose() * f;
  Eigen::Matrix3d strain = 0.5 * (s + s.transpose());
  strain.diagonal().array() -= 1.0;
  return strain;
}

// Linear stress of the co-rotational strain.
Eigen::Matrix3d corotated_stress(const Eigen::Matrix3d& rotation, const Eigen::Matrix3d& f,
                                 const LameParameters& lame) {
  const Eigen::Matrix3d strain = corotated_strain(rotation, f);
  Eigen::Matrix3d stress = 2.0 * lame.mu_pa * strain;
  stress.diagonal().array() += lame.lambda_pa * strain.trace();
  return stress;
}

}  // namespace

CorotationalElasticity::CorotationalElasticity(const TetMesh& mesh, const Material& material)
    : m_tets(mesh.tets), m_lame((validate(material), lame_parameters(material))) {
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
}

void CorotationalElasticity::reset_rotations() {
  std::fill(m_rotations.begin(), m_rotations.end(), Eigen::Matrix3d::Identity());
  std::fill(m_warm_starts.begin(), m_warm_starts.end(), Eigen::Quaterniond::Identity());
}

void CorotationalElasticity::evaluate(const Eigen::VectorXd& positions_m, Eigen::VectorXd& internal_forces_n,
                                      BlockSparseMatrix* tangent, const std::vector<TetSlots>* slots) {
  assert(tangent == nullptr || (slots != nullptr && slots->size() == m_tets.size()));
  const double lambda = m_lame.lambda_pa;
  const double mu = m_lame.mu_pa;
  for (size_t t = 0; t < m_tets.size(); ++t) {
    const Tet& tet = m_tets[t];
    const TetRest& rest = m_rest[t];
    const Eigen::Matrix<double, 3, 4>& g = rest.shape_gradients_per_m;
    const Eigen::Matrix3d f = deformation_gradient(rest, gather(positions_m, tet));
    const Eigen::Matrix3d& r = m_rotations[t] = extract_rotation(f, m_warm_starts[t]);

    // f_i = V R sigma g_i (equal to R K_e (R^T x - X), see DESIGN section 4).
    const Eigen::Matrix3d r_stress_v = rest.volume_m3 * (r * corotated_stress(r, f, m_lame));
    for (int i = 0; i < 4; ++i) internal_forces_n.segment<3>(3 * tet[static_cast<size_t>(i)]) += r_stress_v * g.col(i);

    if (tangent == nullptr) continue;
    const Eigen::Matrix<double, 3, 4> c = r * g;  // rotated shape gradients
    const double lambda_v = lambda * rest.volume_m3;
    const double mu_v = mu * rest.volume_m3;
    const TetSlots& tet_slots = (*slots)[t];
    for (int i = 0; i < 4; ++i) {
      for (int j = i; j < 4; ++j) {
        const int slot_ij = tet_slots[static_cast<size_t>(4 * i + j)];
        if (slot_ij < 0) continue;
        Eigen::Matrix3d block = lambda_v * c.col(i) * c.col(j).transpose() + mu_v * c.col(j) * c.col(i).transpose();
        block.diagonal().array() += mu_v * g.col(i).dot(g.col(j));
        tangent->block(slot_ij) += block;
        if (i != j) tangent->block(tet_slots[static_cast<size_t>(4 * j + i)]) += block.transpose();
      }
    }
  }
}

double CorotationalElasticity::elastic_energy_j(const Eigen::VectorXd& positions_m) const {
  double energy = 0.0;
  for (size_t t = 0; t < m_tets.size(); ++t) {
    const Eigen::Matrix3d f = deformation_gradient(m_rest[t], gather(positions_m, m_tets[t]));
    Eigen::Quaterniond warm_start = m_warm_starts[t];  // a copy: reporting must not change the dynamics
    const Eigen::Matrix3d strain = corotated_strain(extract_rotation(f, warm_start), f);
    energy += m_rest[t].volume_m3 *
              (m_lame.mu_pa * strain.squaredNorm() + 0.5 * m_lame.lambda_pa * strain.trace() * strain.trace());
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
