// XFEM cut-tet forces and tangent (see xfem_elasticity.hpp), in the rotated-gradient form of the
// uncut model: each part costs one deformation gradient, one rotation and one stress; the 8x8
// blocks of eq. 4.3-4.6 are sums of the two parts' rotated blocks with coefficients 0 or +-w_p.
#include "core/fem/xfem_elasticity.hpp"

#include "core/fem/corotational_kernel.hpp"

#include <cassert>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

constexpr std::array<CutPart, 2> PARTS{CutPart::above, CutPart::below};

size_t to_size(int i) { return static_cast<size_t>(i); }

}  // namespace

TetPositions cut_part_positions(const CutTet& cut_tet, CutPart part, const TetPositions& real_positions_m,
                                const TetPositions& enrichment_m) {
  TetPositions p;
  for (int j = 0; j < 4; ++j)
    p[to_size(j)] = real_positions_m[to_size(j)] +
                    cut_tet.shift(j, part) * (enrichment_m[to_size(j)] - cut_tet.enrichment_offset_m[to_size(j)]);
  return p;
}

void XfemElasticity::reserve(int cut_tets) {
  const size_t n = to_size(cut_tets);
  m_cut_tets.reserve(n);
  m_rest.reserve(n);
  m_slots.reserve(n);
  m_rotations.reserve(n);
  m_warm_starts.reserve(n);
}

void XfemElasticity::add(const CutTet& cut_tet, const TetRest& rest, const Eigen::Matrix3d& rotation) {
  m_cut_tets.push_back(cut_tet);
  m_rest.push_back(rest);
  CutTetSlots none;
  none.fill(-1);
  m_slots.push_back(none);
  m_rotations.push_back({rotation, rotation});
  const Eigen::Quaterniond warm_start(rotation);
  m_warm_starts.push_back({warm_start, warm_start});
}

void XfemElasticity::restore_rotations(const std::vector<std::array<Eigen::Matrix3d, 2>>& rotations,
                                       const std::vector<std::array<Eigen::Quaterniond, 2>>& warm_starts) {
  if (rotations.size() != m_cut_tets.size() || warm_starts.size() != m_cut_tets.size()) {
    throw std::invalid_argument("XFEM: expected the parts' rotations of " + std::to_string(m_cut_tets.size()) +
                                " cut tets, got " + std::to_string(rotations.size()) + " and " +
                                std::to_string(warm_starts.size()));
  }
  m_rotations = rotations;
  m_warm_starts = warm_starts;
}

void XfemElasticity::reset_rotations() {
  for (auto& r : m_rotations) r.fill(Eigen::Matrix3d::Identity());
  for (auto& q : m_warm_starts) q.fill(Eigen::Quaterniond::Identity());
}

void XfemElasticity::gather(size_t k, const Eigen::VectorXd& positions_m, const Eigen::VectorXd& displacement_m,
                            TetPositions& real_m, TetPositions& enrichment_m) const {
  const CutTet& cut_tet = m_cut_tets[k];
  for (size_t j = 0; j < 4; ++j) {
    real_m[j] = positions_m.segment<3>(3 * cut_tet.vertices[j]);
    enrichment_m[j] = displacement_m.segment<3>(3 * cut_tet.enriched_row[j]);
  }
}

void XfemElasticity::evaluate(const Eigen::VectorXd& positions_m, const Eigen::VectorXd& displacement_m,
                              Eigen::VectorXd& vertex_forces_n, Eigen::VectorXd& internal_force_n,
                              BlockSparseMatrix* tangent) {
  TetPositions real_m;
  TetPositions enrichment_m;
  for (size_t k = 0; k < m_cut_tets.size(); ++k) {
    const CutTet& cut_tet = m_cut_tets[k];
    const TetRest& rest = m_rest[k];
    gather(k, positions_m, displacement_m, real_m, enrichment_m);

    // Per part: F_p, R_p (warm-started per part) and the part's nodal forces Fp_i.
    std::array<Eigen::Matrix<double, 3, 4>, 2> part_forces;
    for (size_t p = 0; p < 2; ++p) {
      const Eigen::Matrix3d f = deformation_gradient(rest, cut_part_positions(cut_tet, PARTS[p], real_m, enrichment_m));
      const Eigen::Matrix3d& r = m_rotations[k][p] = extract_rotation(f, m_warm_starts[k][p], m_rotation_settings);
      part_forces[p] = corotated_forces(rest, r, f, m_lame);
    }

    // eq. 3.31-3.32.
    const double w_a = cut_tet.weight_above;
    const double w_b = cut_tet.weight_below;
    for (int i = 0; i < 4; ++i) {
      const auto fa = part_forces[0].col(i);
      const auto fb = part_forces[1].col(i);
      vertex_forces_n.segment<3>(3 * cut_tet.vertices[to_size(i)]) += w_a * fa + w_b * fb;
      internal_force_n.segment<3>(3 * cut_tet.enriched_row[to_size(i)]) +=
          w_a * cut_tet.shift(i, CutPart::above) * fa + w_b * cut_tet.shift(i, CutPart::below) * fb;
    }

    if (tangent == nullptr) continue;
    // Rotated blocks R_p K_ij R_p^T of both parts for i <= j (the others are their transposes).
    std::array<std::array<Eigen::Matrix3d, 16>, 2> blocks;
    for (size_t p = 0; p < 2; ++p) {
      const Eigen::Matrix<double, 3, 4> c = m_rotations[k][p] * rest.shape_gradients_per_m;
      for (int i = 0; i < 4; ++i) {
        for (int j = i; j < 4; ++j) blocks[p][to_size(4 * i + j)] = rotated_stiffness_block(rest, m_lame, c, i, j);
      }
    }
    // s_p(I): 1 for u (I < 4), Psi_pi for a (I >= 4); block (I, J) = sum_p w_p s_p(I) s_p(J) R_p K_ij R_p^T.
    std::array<std::array<double, 8>, 2> scale;
    for (size_t p = 0; p < 2; ++p) {
      for (int i = 0; i < 4; ++i) {
        scale[p][to_size(i)] = cut_tet.weight(PARTS[p]);  // the weight folded into the row factor
        scale[p][to_size(i + 4)] = cut_tet.weight(PARTS[p]) * cut_tet.shift(i, PARTS[p]);
      }
    }
    const CutTetSlots& slots = m_slots[k];
    for (int row = 0; row < 8; ++row) {
      for (int col = row; col < 8; ++col) {
        const int slot = slots[to_size(8 * row + col)];
        if (slot < 0) continue;
        const int i = row % 4;
        const int j = col % 4;
        Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
        for (size_t p = 0; p < 2; ++p) {
          // w_p s(I) s(J) = scale(I) * s(J); s(J) = 1 or Psi_pj.
          const double coefficient = scale[p][to_size(row)] * (col < 4 ? 1.0 : cut_tet.shift(j, PARTS[p]));
          if (coefficient == 0.0) continue;
          if (i <= j) {
            block += coefficient * blocks[p][to_size(4 * i + j)];
          } else {
            block += coefficient * blocks[p][to_size(4 * j + i)].transpose();
          }
        }
        tangent->block(slot) += block;
        if (row != col) {
          assert(slots[to_size(8 * col + row)] >= 0);
          tangent->block(slots[to_size(8 * col + row)]) += block.transpose();
        }
      }
    }
  }
}

double XfemElasticity::elastic_energy_j(const Eigen::VectorXd& positions_m,
                                        const Eigen::VectorXd& displacement_m) const {
  double energy = 0.0;
  TetPositions real_m;
  TetPositions enrichment_m;
  for (size_t k = 0; k < m_cut_tets.size(); ++k) {
    gather(k, positions_m, displacement_m, real_m, enrichment_m);
    for (size_t p = 0; p < 2; ++p) {
      const Eigen::Matrix3d f =
          deformation_gradient(m_rest[k], cut_part_positions(m_cut_tets[k], PARTS[p], real_m, enrichment_m));
      Eigen::Quaterniond warm_start = m_warm_starts[k][p];  // a copy: reporting must not change the dynamics
      energy +=
          m_cut_tets[k].weight(PARTS[p]) * corotated_energy_j(m_rest[k], extract_rotation(f, warm_start, m_rotation_settings), f, m_lame);
    }
  }
  return energy;
}

}  // namespace tissue
