// XFEM cut-tet forces and tangent (see xfem_elasticity.hpp), in the rotated-gradient form of the
// uncut model: each piece costs one deformation gradient, one rotation and one stress, and is a
// tet element over its own 4 DOFs (a real vertex's u or a ghost's c), weighted by w_p.
#include "core/fem/xfem_elasticity.hpp"

#include "core/fem/corotational_kernel.hpp"
#include "core/fem/element_blocks.hpp"
#include "core/fem/rotation.hpp"
#include "core/index_cast.hpp"
#include "core/system/hot_kernel.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

// The co-rotational tangent's missing term where it stiffens (TWIST_STIFFNESS_STRAIN): the twists
// Q_ab = U (e_a e_b^T - e_b e_a^T) V^T / sqrt 2 of F = U diag(s) V^T (S = sym(R^T F) = V diag(s) V^T,
// U = R V) have the energy's second derivative e_ab = 2 mu + 2 (lambda (tr S - 3) - 2 mu) / (s_a + s_b),
// which R K R^T leaves at 0 (R^T Q_ab is skew: no strain); where it is positive (a stretched element
// resists turning) V e_ab (Q_ab g_i)(Q_ab g_j)^T is added to block (i, j). Exact where all three are
// positive, and positive semi-definite always.
void add_twist_stiffness(const TetSlots& slots, BlockSparseMatrix& tangent, const Eigen::Matrix<double, 3, 4>& g,
                         const LameParameters& lame, double volume_m3, const Eigen::Matrix3d& rotation,
                         const Eigen::Matrix3d& gradient) {
  const Eigen::Matrix3d stretch = 0.5 * (rotation.transpose() * gradient + gradient.transpose() * rotation);
  if (!((stretch - Eigen::Matrix3d::Identity()).squaredNorm() > TWIST_STIFFNESS_STRAIN * TWIST_STIFFNESS_STRAIN))
    return;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
  eigen.computeDirect(stretch);
  const Eigen::Vector3d& s = eigen.eigenvalues();
  const Eigen::Matrix3d& v = eigen.eigenvectors();
  const Eigen::Matrix3d u = rotation * v;
  const double trace_excess = s.sum() - 3.0;
  constexpr std::array<std::array<int, 2>, 3> PAIRS{{{0, 1}, {0, 2}, {1, 2}}};
  std::array<std::array<Eigen::Vector3d, 4>, 3> t;  // per positive twist k: Q_k g_i, scaled by sqrt(V e_k)
  int twists = 0;
  for (const auto& [a, b] : PAIRS) {
    const double sum = s[a] + s[b];
    if (!(sum > 0.0)) continue;
    const double stiffness = 2.0 * lame.mu_pa + 2.0 * (lame.lambda_pa * trace_excess - 2.0 * lame.mu_pa) / sum;
    if (!(stiffness > 0.0)) continue;
    const Eigen::Matrix3d twist =
        std::sqrt(0.5 * volume_m3 * stiffness) * (u.col(a) * v.col(b).transpose() - u.col(b) * v.col(a).transpose());
    for (int i = 0; i < 4; ++i) t[static_cast<size_t>(twists)][static_cast<size_t>(i)] = twist * g.col(i);
    ++twists;
  }
  if (twists == 0) return;
  element_blocks::add_blocks(slots, tangent, [&](int i, int j) -> Eigen::Matrix3d {
    Eigen::Matrix3d block = Eigen::Matrix3d::Zero();
    for (int k = 0; k < twists; ++k) {
      block.noalias() += t[static_cast<size_t>(k)][static_cast<size_t>(i)] *
                         t[static_cast<size_t>(k)][static_cast<size_t>(j)].transpose();
    }
    return block;
  });
}

constexpr std::array<CutPart, 2> PARTS{CutPart::above, CutPart::below};

Eigen::Index to_int(size_t i) { return static_cast<Eigen::Index>(i); }

}  // namespace

std::array<CutPiece, 2> pieces_of(const CutTet& cut_tet) {
  std::array<CutPiece, 2> pieces;
  for (size_t p = 0; p < 2; ++p) {
    CutPiece& piece = pieces[p];
    piece.weight = cut_tet.weight(PARTS[p]);
    for (int j = 0; j < 4; ++j) {
      const double shift = cut_tet.shift(j, PARTS[p]);
      if (shift == 0.0) continue;  // the real vertex
      piece.ghost_row[to_size(j)] = cut_tet.enriched_row[to_size(j)];
      piece.offset_m[to_size(j)] = cut_tet.enrichment_offset_m[to_size(j)];
    }
  }
  return pieces;
}

void XfemElasticity::reserve(int cut_tets) {
  const size_t n = to_size(cut_tets);
  m_cut_tets.reserve(n);
  m_rest.reserve(n);
  m_retired.reserve(n);
  m_parked.reserve(2 * n);
  m_piece_begin.reserve(n + 1);
  m_pieces.reserve(2 * n);
  m_ghost_dofs.reserve(2 * n);
  m_rotations.reserve(2 * n);
  m_warm_starts.reserve(2 * n);
  m_turns_before.reserve(2 * n);
  m_gradients.reserve(2 * n);
  m_ghost_begin.reserve(n + 1);
  m_ghost_rows.reserve(4 * n);
  m_slot_begin.reserve(n + 1);
  m_slots.reserve(64 * n);
}

void XfemElasticity::add(const CutTet& cut_tet, const TetRest& rest, const Eigen::Matrix3d& rotation) {
  const std::array<CutPiece, 2> two = pieces_of(cut_tet);
  const std::array<Eigen::Matrix3d, 2> rotations{rotation, rotation};
  add(cut_tet, two, rest, rotations);
}

void XfemElasticity::add(const CutTet& cut_tet, std::span<const CutPiece> pieces, const TetRest& rest,
                         std::span<const Eigen::Matrix3d> rotations) {
  if (pieces.size() < 2) throw std::invalid_argument("XFEM: a cut tet needs two pieces or more");
  if (rotations.size() != pieces.size()) throw std::invalid_argument("XFEM: one start rotation per piece");
  const int list = list_of(cut_tet);
  double total = 0.0;
  const std::size_t first_ghost = m_ghost_rows.size();
  const auto ghost_rows = [&] { return std::span<const int>(m_ghost_rows).subspan(first_ghost); };
  for (const CutPiece& piece : pieces) {
    if (!(piece.weight > 0.0)) throw std::invalid_argument("XFEM: a piece's weight is not positive");
    total += piece.weight;
  }
  if (std::abs(total - 1.0) > 1e-12) {
    throw std::invalid_argument("XFEM: the pieces' weights add up to " + std::to_string(total) + ", not 1");
  }
  for (const CutPiece& piece : pieces) {
    for (size_t j = 0; j < 4; ++j) {
      const int row = piece.ghost_row[j];
      const std::span<const int> rows = ghost_rows();
      if (row >= 0 && std::find(rows.begin(), rows.end(), row) == rows.end()) m_ghost_rows.push_back(row);
    }
  }
  m_ghost_begin.push_back(static_cast<int>(m_ghost_rows.size()));
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const CutPiece& piece = pieces[p];
    std::array<int, 4> dofs{};
    const std::span<const int> rows = ghost_rows();
    for (size_t j = 0; j < 4; ++j) {
      const int row = piece.ghost_row[j];
      dofs[j] = row < 0 ? -1 : 4 + static_cast<int>(std::find(rows.begin(), rows.end(), row) - rows.begin());
    }
    m_pieces.push_back(piece);
    m_parked.push_back(0);
    m_ghost_dofs.push_back(dofs);
    m_rotations.push_back(rotations[p]);
    m_warm_starts.emplace_back(rotations[p]);
    m_turns_before.emplace_back(rotations[p]);
  }
  m_piece_begin.push_back(static_cast<int>(m_pieces.size()));
  const std::size_t dofs = 4 + ghost_rows().size();
  m_slots.insert(m_slots.end(), dofs * dofs, -1);
  m_slot_begin.push_back(m_slots.size());
  m_lists[static_cast<std::size_t>(list)].push_back(static_cast<int>(m_cut_tets.size()));
  m_cut_tets.push_back(cut_tet);
  m_rest.push_back(rest);
  m_retired.push_back(0);
}

namespace {

// The list of `tet` in a set_assembly_lists table; std::invalid_argument for a tet it lacks.
int list_in(const std::vector<int>& list_of_tet, int tet) {
  if (tet < 0 || static_cast<std::size_t>(tet) >= list_of_tet.size()) {
    throw std::invalid_argument("XFEM: tet " + std::to_string(tet) + " has no assembly list");
  }
  return list_of_tet[static_cast<std::size_t>(tet)];
}

}  // namespace

void XfemElasticity::set_assembly_lists(std::vector<int> list_of_tet, int phases) {
  if (phases < 0) throw std::invalid_argument("XFEM: " + std::to_string(phases) + " assembly phases");
  const int list_count = LIST_PARTS * phases + 1;
  for (const int list : list_of_tet) {
    if (list < 0 || list >= list_count) {
      throw std::invalid_argument("XFEM: assembly list " + std::to_string(list) + " of " + std::to_string(list_count));
    }
  }
  std::vector<std::vector<int>> lists(static_cast<std::size_t>(list_count));
  for (std::size_t k = 0; k < m_cut_tets.size(); ++k) {
    lists[static_cast<std::size_t>(list_in(list_of_tet, m_cut_tets[k].cut.tet))].push_back(static_cast<int>(k));
  }
  m_list_of_tet = std::move(list_of_tet);
  m_lists = std::move(lists);
}

int XfemElasticity::list_of(const CutTet& cut_tet) const {
  return m_list_of_tet.empty() ? 0 : list_in(m_list_of_tet, cut_tet.cut.tet);
}

template <class Job>
double XfemElasticity::sum_over_lists(WorkTeam* team, Job&& job) const {
  const auto phases = static_cast<int>((m_lists.size() - 1) / LIST_PARTS);
  const double phased = sum_over_phases(team, phases, [&](int phase, int part) {
    return job(m_lists[static_cast<std::size_t>(LIST_PARTS * phase + part)]);
  });
  return phased + job(m_lists.back());
}

bool XfemElasticity::all_parked(int k) const {
  const std::size_t begin = piece_begin(k);
  return std::all_of(m_parked.begin() + static_cast<long>(begin),
                     m_parked.begin() + static_cast<long>(begin + piece_count(k)), [](std::uint8_t p) { return p != 0; });
}

std::array<int, 4> XfemElasticity::piece_dofs(std::size_t p) const {
  std::array<int, 4> dof{};
  for (int i = 0; i < 4; ++i) {
    const int ghost = m_ghost_dofs[p][to_size(i)];
    dof[to_size(i)] = ghost < 0 ? i : ghost;
  }
  return dof;
}

void XfemElasticity::mark_written_slots(int k, std::vector<std::uint8_t>& keep) const {
  const int* const slots = m_slots.data() + m_slot_begin[static_cast<std::size_t>(k)];
  std::vector<std::uint8_t> coupled;
  coupled_dofs(k, coupled);
  for (std::size_t pair = 0; pair < coupled.size(); ++pair) {
    if (coupled[pair] != 0 && slots[pair] >= 0) keep[static_cast<std::size_t>(slots[pair])] = 1;
  }
}

void XfemElasticity::coupled_dofs(int k, std::vector<std::uint8_t>& coupled) const {
  const int dofs = dof_count(k);
  coupled.assign(to_size(dofs * dofs), 0);
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < 4; ++b) coupled[to_size(dofs * a + b)] = 1;  // the uncut tet's blocks (kept)
  }
  const std::size_t begin = piece_begin(k);
  for (std::size_t p = begin; p < begin + piece_count(k); ++p) {
    if (m_parked[p] != 0) continue;
    const std::array<int, 4> dof = piece_dofs(p);
    for (const int a : dof) {
      for (const int b : dof) coupled[to_size(dofs * a + b)] = 1;
    }
  }
}

void XfemElasticity::restore_rotations(const std::vector<Eigen::Matrix3d>& rotations,
                                       const std::vector<Eigen::Quaterniond>& warm_starts,
                                       const std::vector<Eigen::Quaterniond>& turns_before) {
  if (rotations.size() != m_rotations.size() || warm_starts.size() != m_warm_starts.size() ||
      turns_before.size() != m_turns_before.size()) {
    throw std::invalid_argument("XFEM: expected the rotations of " + std::to_string(m_rotations.size()) +
                                " cut-tet pieces, got " + std::to_string(rotations.size()) + ", " +
                                std::to_string(warm_starts.size()) + " and " + std::to_string(turns_before.size()));
  }
  m_rotations = rotations;
  m_warm_starts = warm_starts;
  m_turns_before = turns_before;
}

void XfemElasticity::reset_rotations() {
  std::fill(m_rotations.begin(), m_rotations.end(), Eigen::Matrix3d::Identity());
  std::fill(m_warm_starts.begin(), m_warm_starts.end(), Eigen::Quaterniond::Identity());
  std::fill(m_turns_before.begin(), m_turns_before.end(), Eigen::Quaterniond::Identity());
}

void XfemElasticity::gather(size_t k, const Eigen::VectorXd& positions_m, TetPositions& real_m) const {
  const CutTet& cut_tet = m_cut_tets[k];
  for (size_t j = 0; j < 4; ++j) real_m[j] = positions_m.segment<3>(3 * cut_tet.vertices[j]);
}

TetPositions piece_positions(const CutPiece& piece, const TetPositions& real_positions_m,
                             const TetPositions& rest_positions_m, const Eigen::VectorXd& displacement_m) {
  TetPositions p = real_positions_m;
  for (size_t j = 0; j < 4; ++j) {
    if (piece.ghost_row[j] < 0) continue;
    p[j] = rest_positions_m[j] + (displacement_m.segment<3>(3 * piece.ghost_row[j]) - piece.offset_m[j]);
  }
  return p;
}

// Each counted piece of `cut_tets`, in their order, its F and, in SIMD lanes four pieces at a time,
// its rotation (extract_rotations, as the uncut tets' in_rotation_batches): visit(p, k, F, R) for
// piece p of cut tet k. With `warm_starts`, into `rotations` from extrapolated_turn(warm start, turn
// before), `keep` keeping the warm starts replaced as the turns before; without (nullptr), from copies
// of the pieces' own warm starts, which stay as they are (reporting must not change the dynamics).
template <class Visit>
void XfemElasticity::in_piece_rotation_batches(const std::vector<int>& cut_tets, const Eigen::VectorXd& positions_m,
                                               const Eigen::VectorXd& displacement_m,
                                               std::vector<Eigen::Quaterniond>* warm_starts,
                                               std::vector<Eigen::Matrix3d>* rotations,
                                               std::vector<Eigen::Quaterniond>* turns_before, bool keep,
                                               Visit visit) const {
  std::array<Eigen::Matrix3d, ROTATION_BATCH> gradients;
  std::array<Eigen::Quaterniond, ROTATION_BATCH> warm_start_copies;
  std::array<Eigen::Matrix3d, ROTATION_BATCH> rotation_copies;
  std::array<Eigen::Quaterniond*, ROTATION_BATCH> lane_warm_starts{};
  std::array<Eigen::Matrix3d*, ROTATION_BATCH> lane_rotations{};
  std::array<Eigen::Quaterniond*, ROTATION_BATCH> lane_turns_before{};
  std::array<size_t, ROTATION_BATCH> lane_piece{};
  std::array<size_t, ROTATION_BATCH> lane_tet{};
  const TurnsBefore turns = warm_starts != nullptr ? TurnsBefore{lane_turns_before.data(), keep} : TurnsBefore{};
  int lanes = 0;
  const auto extract = [&] {
    extract_rotations(lanes, gradients.data(), lane_warm_starts.data(), lane_rotations.data(), m_rotation_settings,
                      turns);
    for (size_t lane = 0; lane < to_size(lanes); ++lane) {
      visit(lane_piece[lane], lane_tet[lane], gradients[lane], *lane_rotations[lane]);
    }
    lanes = 0;
  };
  TetPositions real_m;
  for (const int cut_tet : cut_tets) {
    const auto k = static_cast<size_t>(cut_tet);
    if (m_retired[k] != 0 || all_parked(cut_tet)) continue;
    gather(k, positions_m, real_m);
    const std::size_t first = piece_begin(cut_tet);
    for (size_t p = first; p < first + piece_count(cut_tet); ++p) {
      if (m_parked[p] != 0) continue;
      const auto lane = to_size(lanes++);
      gradients[lane] =
          deformation_gradient(m_rest[k], piece_positions(m_pieces[p], real_m, m_cut_tets[k].rest_m, displacement_m));
      lane_piece[lane] = p;
      lane_tet[lane] = k;
      if (warm_starts != nullptr) {
        lane_warm_starts[lane] = &(*warm_starts)[p];
        lane_rotations[lane] = &(*rotations)[p];
        lane_turns_before[lane] = &(*turns_before)[p];
      } else {
        warm_start_copies[lane] = m_warm_starts[p];
        lane_warm_starts[lane] = &warm_start_copies[lane];
        lane_rotations[lane] = &rotation_copies[lane];
      }
      if (lanes == ROTATION_BATCH) extract();
    }
  }
  if (lanes > 0) extract();
}

// Not a hot kernel, so the pieces' F and positions round as they always have in the step (the hot
// kernels' clones contract to FMA).
void XfemElasticity::extract_piece_rotations(const std::vector<int>& cut_tets, const Eigen::VectorXd& positions_m,
                                             const Eigen::VectorXd& displacement_m,
                                             std::vector<Eigen::Matrix3d>& rotations,
                                             std::vector<Eigen::Quaterniond>& warm_starts, bool keep) {
  in_piece_rotation_batches(
      cut_tets, positions_m, displacement_m, &warm_starts, &rotations, &m_turns_before, keep,
      [&](size_t p, size_t /*k*/, const Eigen::Matrix3d& f, const Eigen::Matrix3d& /*r*/) { m_gradients[p] = f; });
}

void XfemElasticity::evaluate(const Eigen::VectorXd& positions_m, const Eigen::VectorXd& displacement_m,
                              Eigen::VectorXd& vertex_forces_n, Eigen::VectorXd& internal_force_n,
                              BlockSparseMatrix* tangent, double* elastic_energy_j, ExtractInto into, WorkTeam* team) {
  // Ahead: every piece's as it is first (retired and parked ones keep theirs), then extracted there.
  if (into == ExtractInto::ahead) {
    m_rotations_ahead = m_rotations;
    m_warm_starts_ahead = m_warm_starts;
  }
  m_gradients.resize(m_pieces.size());
  const Pass pass{positions_m,
                  displacement_m,
                  vertex_forces_n,
                  internal_force_n,
                  tangent,
                  into == ExtractInto::ahead ? m_rotations_ahead : m_rotations,
                  into == ExtractInto::ahead ? m_warm_starts_ahead : m_warm_starts,
                  into == ExtractInto::own,
                  elastic_energy_j != nullptr};
  const double energy = sum_over_lists(team, [&](const std::vector<int>& list) { return evaluate_list(list, pass); });
  if (elastic_energy_j != nullptr) *elastic_energy_j = energy;
}

TISSUE_HOT_KERNEL double XfemElasticity::evaluate_list(const std::vector<int>& cut_tets, const Pass& pass) {
  extract_piece_rotations(cut_tets, pass.positions_m, pass.displacement_m, pass.rotations, pass.warm_starts, pass.keep);
  BlockSparseMatrix* const tangent = pass.tangent;
  double energy = 0.0;
  for (const int cut_tet_index : cut_tets) {
    const auto k = static_cast<size_t>(cut_tet_index);
    if (m_retired[k] != 0 || all_parked(cut_tet_index)) continue;
    const CutTet& cut_tet = m_cut_tets[k];
    const TetRest& rest = m_rest[k];
    const std::size_t first = piece_begin(cut_tet_index);
    const std::size_t count = piece_count(cut_tet_index);
    const int dofs = dof_count(cut_tet_index);
    const int* const slots = m_slots.data() + m_slot_begin[k];
    // Per piece: its nodal forces Fp_i and, through the slots of its local DOFs, its blocks (each
    // piece's block of two real vertices added on its own, as a tet's).
    Eigen::Matrix<double, 3, 4> vertex_sum = Eigen::Matrix<double, 3, 4>::Zero();
    for (size_t p = first; p < first + count; ++p) {
      if (m_parked[p] != 0) continue;
      const CutPiece& piece = m_pieces[p];
      const Eigen::Matrix3d& f = m_gradients[p];
      const Eigen::Matrix3d& r = pass.rotations[p];
      const Eigen::Matrix<double, 3, 4> forces = m_elements.forces(rest, r, f);
      if (pass.with_energy) energy += piece.weight * m_elements.energy_j(rest, r, f);
      for (size_t i = 0; i < 4; ++i) {
        if (piece.ghost_row[i] < 0) {
          vertex_sum.col(to_int(i)) += piece.weight * forces.col(to_int(i));
        } else {
          pass.internal_force_n.segment<3>(3 * piece.ghost_row[i]) += piece.weight * forces.col(to_int(i));
        }
      }
      if (tangent == nullptr) continue;
      const std::array<int, 4> dof = piece_dofs(p);
      TetSlots piece_slots{};
      for (size_t i = 0; i < 4; ++i) {
        for (size_t j = 0; j < 4; ++j) piece_slots[4 * i + j] = slots[dofs * dof[i] + dof[j]];
      }
      if (m_elements.model == MaterialModel::corotational_linear) {
        element_blocks::add_rotated_stiffness_blocks(piece_slots, *tangent, rest.shape_gradients_per_m,
                                                     m_elements.lame_of(rest), piece.weight * rest.volume_m3, r);
        add_twist_stiffness(piece_slots, *tangent, rest.shape_gradients_per_m, m_elements.lame_of(rest),
                            piece.weight * rest.volume_m3, r, f);
        continue;
      }
      std::array<Eigen::Matrix3d, 16> blocks;
      m_elements.blocks(rest, r, f, blocks);
      element_blocks::add_blocks(piece_slots, *tangent,
                                 [&](int i, int j) { return piece.weight * blocks[to_size(4 * i + j)]; });
    }
    for (int i = 0; i < 4; ++i) pass.vertex_forces_n.segment<3>(3 * cut_tet.vertices[to_size(i)]) += vertex_sum.col(i);
  }
  return energy;
}

double XfemElasticity::elastic_energy_j(const Eigen::VectorXd& positions_m, const Eigen::VectorXd& displacement_m,
                                        WorkTeam* team) const {
  return sum_over_lists(team,
                        [&](const std::vector<int>& list) { return energy_of(list, positions_m, displacement_m); });
}

// The pieces' rotations as a step extracts them, from copies of the warm starts; the terms added in
// the pieces' order.
TISSUE_HOT_KERNEL double XfemElasticity::energy_of(const std::vector<int>& cut_tets, const Eigen::VectorXd& positions_m,
                                                   const Eigen::VectorXd& displacement_m) const {
  double energy = 0.0;
  in_piece_rotation_batches(cut_tets, positions_m, displacement_m, nullptr, nullptr, nullptr, false,
                            [&](size_t p, size_t k, const Eigen::Matrix3d& f, const Eigen::Matrix3d& r) {
                              energy += m_pieces[p].weight * m_elements.energy_j(m_rest[k], r, f);
                            });
  return energy;
}

}  // namespace tissue
