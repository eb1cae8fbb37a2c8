// XFEM cut-tet forces and tangent (see xfem_elasticity.hpp), in the rotated-gradient form of the
// uncut model: each part costs one deformation gradient, one rotation and one stress; the 8x8
// blocks of eq. 4.3-4.6 are sums of the two parts' rotated blocks with coefficients 0 or +-w_p.
#include "core/fem/xfem_elasticity.hpp"

#include "core/fem/corotational_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

constexpr std::array<CutPart, 2> PARTS{CutPart::above, CutPart::below};

size_t to_size(int i) { return static_cast<size_t>(i); }
Eigen::Index to_int(size_t i) { return static_cast<Eigen::Index>(i); }

}  // namespace

TetPositions cut_part_positions(const CutTet& cut_tet, CutPart part, const TetPositions& real_positions_m,
                                const TetPositions& enrichment_m) {
  TetPositions p;
  for (int j = 0; j < 4; ++j)
    p[to_size(j)] = real_positions_m[to_size(j)] +
                    cut_tet.shift(j, part) * (enrichment_m[to_size(j)] - cut_tet.enrichment_offset_m[to_size(j)]);
  return p;
}

std::array<CutPiece, 2> pieces_of(const CutTet& cut_tet) {
  std::array<CutPiece, 2> pieces;
  for (size_t p = 0; p < 2; ++p) {
    CutPiece& piece = pieces[p];
    piece.weight = cut_tet.weight(PARTS[p]);
    for (int j = 0; j < 4; ++j) {
      const double shift = cut_tet.shift(j, PARTS[p]);
      if (shift == 0.0) continue;  // the real vertex
      piece.ghost_row[to_size(j)] = cut_tet.enriched_row[to_size(j)];
      piece.ghost_sign[to_size(j)] = shift;
      piece.offset_m[to_size(j)] = cut_tet.enrichment_offset_m[to_size(j)];
    }
  }
  return pieces;
}

void XfemElasticity::reserve(int cut_tets) {
  const size_t n = to_size(cut_tets);
  m_cut_tets.reserve(n);
  m_rest.reserve(n);
  m_pieces.reserve(n);
  m_ghost_rows.reserve(n);
  m_slots.reserve(n);
  m_rotations.reserve(n);
  m_warm_starts.reserve(n);
}

void XfemElasticity::add(const CutTet& cut_tet, const TetRest& rest, const Eigen::Matrix3d& rotation) {
  const std::array<CutPiece, 2> two = pieces_of(cut_tet);
  add(cut_tet, two, rest, rotation);
}

void XfemElasticity::add(const CutTet& cut_tet, std::span<const CutPiece> pieces, const TetRest& rest,
                         const Eigen::Matrix3d& rotation) {
  if (pieces.size() < 2) throw std::invalid_argument("XFEM: a cut tet needs two pieces or more");
  double total = 0.0;
  std::vector<int> ghost_rows;
  for (const CutPiece& piece : pieces) {
    if (!(piece.weight > 0.0)) throw std::invalid_argument("XFEM: a piece's weight is not positive");
    total += piece.weight;
    for (size_t j = 0; j < 4; ++j) {
      if (piece.ghost_row[j] < 0) continue;
      if (std::abs(piece.ghost_sign[j]) != 1.0) throw std::invalid_argument("XFEM: a ghost's sign is not +-1");
      if (std::find(ghost_rows.begin(), ghost_rows.end(), piece.ghost_row[j]) == ghost_rows.end()) {
        ghost_rows.push_back(piece.ghost_row[j]);
      }
    }
  }
  if (std::abs(total - 1.0) > 1e-12) {
    throw std::invalid_argument("XFEM: the pieces' weights add up to " + std::to_string(total) + ", not 1");
  }
  m_cut_tets.push_back(cut_tet);
  m_rest.push_back(rest);
  m_pieces.emplace_back(pieces.begin(), pieces.end());
  const size_t dofs = 4 + ghost_rows.size();
  m_ghost_rows.push_back(std::move(ghost_rows));
  m_slots.emplace_back(dofs * dofs, -1);
  m_rotations.emplace_back(pieces.size(), rotation);
  m_warm_starts.emplace_back(pieces.size(), Eigen::Quaterniond(rotation));
}

bool XfemElasticity::couples(int k, int dof_i, int dof_j) const {
  if (dof_i < 4 && dof_j < 4) return true;
  const std::vector<int>& ghosts = m_ghost_rows[to_size(k)];
  const auto uses = [&](const CutPiece& piece, int dof) {
    if (dof < 4) return true;
    const int row = ghosts[to_size(dof - 4)];
    return std::find(piece.ghost_row.begin(), piece.ghost_row.end(), row) != piece.ghost_row.end();
  };
  for (const CutPiece& piece : m_pieces[to_size(k)]) {
    if (uses(piece, dof_i) && uses(piece, dof_j)) return true;
  }
  return false;
}

std::vector<std::array<Eigen::Matrix3d, 2>> XfemElasticity::rotations() const {
  std::vector<std::array<Eigen::Matrix3d, 2>> out;
  out.reserve(m_rotations.size());
  for (const auto& r : m_rotations) out.push_back({r[0], r[1]});
  return out;
}

std::vector<std::array<Eigen::Quaterniond, 2>> XfemElasticity::warm_starts() const {
  std::vector<std::array<Eigen::Quaterniond, 2>> out;
  out.reserve(m_warm_starts.size());
  for (const auto& q : m_warm_starts) out.push_back({q[0], q[1]});
  return out;
}

void XfemElasticity::restore_rotations(const std::vector<std::array<Eigen::Matrix3d, 2>>& rotations,
                                       const std::vector<std::array<Eigen::Quaterniond, 2>>& warm_starts) {
  if (rotations.size() != m_cut_tets.size() || warm_starts.size() != m_cut_tets.size()) {
    throw std::invalid_argument("XFEM: expected the parts' rotations of " + std::to_string(m_cut_tets.size()) +
                                " cut tets, got " + std::to_string(rotations.size()) + " and " +
                                std::to_string(warm_starts.size()));
  }
  for (const auto& pieces : m_pieces) {
    if (pieces.size() != 2) throw std::invalid_argument("XFEM: a state holds the rotations of two pieces per cut tet");
  }
  for (size_t k = 0; k < m_cut_tets.size(); ++k) {
    m_rotations[k] = {rotations[k][0], rotations[k][1]};
    m_warm_starts[k] = {warm_starts[k][0], warm_starts[k][1]};
  }
}

void XfemElasticity::reset_rotations() {
  for (auto& r : m_rotations) std::fill(r.begin(), r.end(), Eigen::Matrix3d::Identity());
  for (auto& q : m_warm_starts) std::fill(q.begin(), q.end(), Eigen::Quaterniond::Identity());
}

void XfemElasticity::gather(size_t k, const Eigen::VectorXd& positions_m, TetPositions& real_m) const {
  const CutTet& cut_tet = m_cut_tets[k];
  for (size_t j = 0; j < 4; ++j) real_m[j] = positions_m.segment<3>(3 * cut_tet.vertices[j]);
}

TetPositions XfemElasticity::piece_positions(const CutPiece& piece, const TetPositions& real_m,
                                             const Eigen::VectorXd& displacement_m) {
  TetPositions p = real_m;
  for (size_t j = 0; j < 4; ++j) {
    if (piece.ghost_row[j] < 0) continue;
    p[j] += piece.ghost_sign[j] * (displacement_m.segment<3>(3 * piece.ghost_row[j]) - piece.offset_m[j]);
  }
  return p;
}

void XfemElasticity::evaluate(const Eigen::VectorXd& positions_m, const Eigen::VectorXd& displacement_m,
                              Eigen::VectorXd& vertex_forces_n, Eigen::VectorXd& internal_force_n,
                              BlockSparseMatrix* tangent) {
  TetPositions real_m;
  for (size_t k = 0; k < m_cut_tets.size(); ++k) {
    const CutTet& cut_tet = m_cut_tets[k];
    const TetRest& rest = m_rest[k];
    const std::vector<CutPiece>& pieces = m_pieces[k];
    gather(k, positions_m, real_m);

    // Per piece: F_p, R_p (warm-started per piece), its nodal forces Fp_i, and what it adds.
    Eigen::Matrix<double, 3, 4> vertex_sum = Eigen::Matrix<double, 3, 4>::Zero();
    for (size_t p = 0; p < pieces.size(); ++p) {
      const CutPiece& piece = pieces[p];
      const Eigen::Matrix3d f = deformation_gradient(rest, piece_positions(piece, real_m, displacement_m));
      const Eigen::Matrix3d& r = m_rotations[k][p] = extract_rotation(f, m_warm_starts[k][p], m_rotation_settings);
      const Eigen::Matrix<double, 3, 4> forces = corotated_forces(rest, r, f, m_lame);
      vertex_sum += piece.weight * forces;
      for (size_t i = 0; i < 4; ++i) {
        if (piece.ghost_row[i] < 0) continue;
        internal_force_n.segment<3>(3 * piece.ghost_row[i]) += piece.weight * piece.ghost_sign[i] * forces.col(to_int(i));
      }
    }
    for (int i = 0; i < 4; ++i) vertex_forces_n.segment<3>(3 * cut_tet.vertices[to_size(i)]) += vertex_sum.col(i);

    if (tangent == nullptr) continue;
    const std::vector<int>& ghosts = m_ghost_rows[k];
    const int dofs = 4 + static_cast<int>(ghosts.size());
    const CutTetSlots& slots = m_slots[k];
    for (size_t p = 0; p < pieces.size(); ++p) {
      const CutPiece& piece = pieces[p];
      // The piece's DOFs: u of each local vertex (coefficient 1), its ghosts (coefficient sign).
      std::array<int, 8> dof{};
      std::array<int, 8> vertex{};
      std::array<double, 8> coefficient{};
      int n = 0;
      for (int i = 0; i < 4; ++i) {
        dof[to_size(n)] = i;
        vertex[to_size(n)] = i;
        coefficient[to_size(n++)] = 1.0;
      }
      for (int i = 0; i < 4; ++i) {
        if (piece.ghost_row[to_size(i)] < 0) continue;
        const auto at = std::find(ghosts.begin(), ghosts.end(), piece.ghost_row[to_size(i)]);
        dof[to_size(n)] = 4 + static_cast<int>(at - ghosts.begin());
        vertex[to_size(n)] = i;
        coefficient[to_size(n++)] = piece.ghost_sign[to_size(i)];
      }
      const Eigen::Matrix<double, 3, 4> c = m_rotations[k][p] * rest.shape_gradients_per_m;
      std::array<Eigen::Matrix3d, 16> blocks;
      for (int i = 0; i < 4; ++i) {
        for (int j = i; j < 4; ++j) blocks[to_size(4 * i + j)] = rotated_stiffness_block(rest, m_lame, c, i, j);
      }
      for (int a = 0; a < n; ++a) {
        for (int b = 0; b < n; ++b) {
          const int slot = slots[to_size(dofs * dof[to_size(a)] + dof[to_size(b)])];
          if (slot < 0) continue;
          const int i = vertex[to_size(a)];
          const int j = vertex[to_size(b)];
          const double w = piece.weight * coefficient[to_size(a)] * coefficient[to_size(b)];
          if (i <= j) {
            tangent->block(slot) += w * blocks[to_size(4 * i + j)];
          } else {
            tangent->block(slot) += w * blocks[to_size(4 * j + i)].transpose();
          }
        }
      }
    }
  }
}

double XfemElasticity::elastic_energy_j(const Eigen::VectorXd& positions_m,
                                        const Eigen::VectorXd& displacement_m) const {
  double energy = 0.0;
  TetPositions real_m;
  for (size_t k = 0; k < m_cut_tets.size(); ++k) {
    gather(k, positions_m, real_m);
    for (size_t p = 0; p < m_pieces[k].size(); ++p) {
      const CutPiece& piece = m_pieces[k][p];
      const Eigen::Matrix3d f = deformation_gradient(m_rest[k], piece_positions(piece, real_m, displacement_m));
      Eigen::Quaterniond warm_start = m_warm_starts[k][p];  // a copy: reporting must not change the dynamics
      energy += piece.weight *
                corotated_energy_j(m_rest[k], extract_rotation(f, warm_start, m_rotation_settings), f, m_lame);
    }
  }
  return energy;
}

}  // namespace tissue
