// Co-rotational forces and tangent, written in the rotated-gradient form: with c_i = R g_i,
//   R K_ij R^T = V [lambda c_i c_j^T + mu c_j c_i^T + mu (g_i . g_j) I],
// which costs ~20 flops per block instead of the 54 of R K_ij R^T (Vega spends three quarters of
// a step rebuilding the rotated stiffness; this is where we win it back).
#include "core/fem/corotational.hpp"

#include "core/fem/corotational_kernel.hpp"
#include "core/fem/element_blocks.hpp"
#include "core/mesh/topology.hpp"
#include "core/system/hot_kernel.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

TetPositions gather(const Eigen::VectorXd& positions_m, const Tet& tet) {
  TetPositions x;
  for (int i = 0; i < 4; ++i) x[static_cast<size_t>(i)] = positions_m.segment<3>(3 * tet[static_cast<size_t>(i)]);
  return x;
}

std::vector<LameParameters> lame_table(const TetMesh& mesh, const std::vector<Material>& materials) {
  if (materials.size() != static_cast<size_t>(mesh.region_count())) {
    throw ParameterError("co-rotational elasticity: " + std::to_string(materials.size()) +
                         " materials for a mesh of " + std::to_string(mesh.region_count()) + " regions");
  }
  std::vector<LameParameters> table;
  for (const Material& material : materials) {
    validate(material);
    table.push_back(lame_parameters(material));
  }
  return table;
}

}  // namespace

CorotationalElasticity::CorotationalElasticity(const TetMesh& mesh, const std::vector<Material>& materials,
                                               const RotationSettings& rotation, const std::vector<int>& vertex_order,
                                               MaterialModel model)
    : m_elements(model, lame_table(mesh, materials)), m_rotation_settings((validate(rotation), rotation)) {
  partition(mesh, vertex_order);
  m_tets.reserve(m_tet_id.size());
  m_rest.reserve(m_tet_id.size());
  for (const int t : m_tet_id) {
    m_tets.push_back(mesh.tets[static_cast<size_t>(t)]);
    m_rest.push_back(precompute_tet(mesh.rest_corners(t)));
    m_rest.back().material = mesh.region_of(t);
  }
  m_rotations.assign(m_tets.size(), Eigen::Matrix3d::Identity());
  m_warm_starts.assign(m_tets.size(), Eigen::Quaterniond::Identity());
  m_rotations_ahead = m_rotations;
  m_warm_starts_ahead = m_warm_starts;
  m_turns_before = m_warm_starts;
  m_excluded.assign(m_tets.size(), 0);
}

namespace {

constexpr int ASSEMBLY_LEVELS = 3;  // the mesh, its separator, that one's: leaves ~3% of the frog alone

// Splits `tets` in two at the median of their centroids along the longest axis of their extent;
// tets that share a vertex with the other half go to `separator`.
void split(const TetMesh& mesh, const std::vector<int>& tets, CorotationalElasticity::AssemblyPhase& halves,
           std::vector<int>& separator, std::vector<unsigned char>& vertex_halves) {
  std::vector<Eigen::Vector3d> centroids(tets.size());
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (size_t k = 0; k < tets.size(); ++k) {
    centroids[k].setZero();
    for (const int v : mesh.tets[static_cast<size_t>(tets[k])]) {
      centroids[k] += 0.25 * mesh.rest_positions_m[static_cast<size_t>(v)];
    }
    low = low.cwiseMin(centroids[k]);
    high = high.cwiseMax(centroids[k]);
  }
  Eigen::Index axis = 0;
  if (!tets.empty()) (high - low).maxCoeff(&axis);
  std::vector<size_t> by_position(tets.size());
  std::iota(by_position.begin(), by_position.end(), size_t{0});
  const auto middle = by_position.begin() + static_cast<std::ptrdiff_t>(tets.size() / 2);
  std::nth_element(by_position.begin(), middle, by_position.end(), [&](size_t a, size_t b) {
    return centroids[a][axis] < centroids[b][axis] || (centroids[a][axis] == centroids[b][axis] && a < b);
  });
  std::vector<int> half(tets.size(), 0);
  for (auto it = middle; it != by_position.end(); ++it) half[*it] = 1;
  std::fill(vertex_halves.begin(), vertex_halves.end(), 0);  // bit h: touched by half h
  for (size_t k = 0; k < tets.size(); ++k) {
    for (const int v : mesh.tets[static_cast<size_t>(tets[k])]) {
      vertex_halves[static_cast<size_t>(v)] |= static_cast<unsigned char>(1 << half[k]);
    }
  }
  for (auto& list : halves) list.clear();
  separator.clear();
  for (size_t k = 0; k < tets.size(); ++k) {
    bool shared = false;
    for (const int v : mesh.tets[static_cast<size_t>(tets[k])]) shared = shared || vertex_halves[static_cast<size_t>(v)] == 3;
    (shared ? separator : halves[static_cast<size_t>(half[k])]).push_back(tets[k]);
  }
}

}  // namespace

void CorotationalElasticity::partition(const TetMesh& mesh, const std::vector<int>& vertex_order) {
  static_assert(ASSEMBLY_PARTS == 2, "split() halves");
  std::vector<int> remaining(mesh.tets.size());
  std::iota(remaining.begin(), remaining.end(), 0);
  std::vector<unsigned char> vertex_halves(static_cast<size_t>(mesh.vertex_count()));
  m_phases.assign(ASSEMBLY_LEVELS, AssemblyPhase{});
  std::vector<int> separator;
  for (AssemblyPhase& phase : m_phases) {
    split(mesh, remaining, phase, separator, vertex_halves);
    remaining.swap(separator);
  }
  m_serial_tets = std::move(remaining);
  sort_lists(mesh, vertex_order);

  // Storage in visiting order; the lists become storage indices.
  m_tet_id.clear();
  for (const AssemblyPhase& phase : m_phases) {
    for (const std::vector<int>& part : phase) m_tet_id.insert(m_tet_id.end(), part.begin(), part.end());
  }
  m_tet_id.insert(m_tet_id.end(), m_serial_tets.begin(), m_serial_tets.end());
  m_storage.assign(m_tet_id.size(), -1);
  for (size_t k = 0; k < m_tet_id.size(); ++k) m_storage[static_cast<size_t>(m_tet_id[k])] = static_cast<int>(k);
  for (AssemblyPhase& phase : m_phases) {
    for (std::vector<int>& part : phase) {
      for (int& t : part) t = m_storage[static_cast<size_t>(t)];
    }
  }
  for (int& t : m_serial_tets) t = m_storage[static_cast<size_t>(t)];
}

std::vector<int> CorotationalElasticity::assembly_list_of_tets() const {
  std::vector<int> list_of_tet(m_tet_id.size(), ASSEMBLY_PARTS * static_cast<int>(m_phases.size()));
  for (size_t phase = 0; phase < m_phases.size(); ++phase) {
    for (size_t part = 0; part < ASSEMBLY_PARTS; ++part) {
      for (const int k : m_phases[phase][part]) {
        list_of_tet[static_cast<size_t>(m_tet_id[static_cast<size_t>(k)])] =
            ASSEMBLY_PARTS * static_cast<int>(phase) + static_cast<int>(part);
      }
    }
  }
  return list_of_tet;
}

void CorotationalElasticity::sort_lists(const TetMesh& mesh, const std::vector<int>& vertex_order) {
  // Each list by the earliest position of its tets' vertices in the order (ties by id).
  if (vertex_order.empty()) return;
  const std::vector<int> rank = order_ranks(vertex_order, mesh.vertex_count(), "CorotationalElasticity");
  std::vector<int> tet_rank(mesh.tets.size());
  for (size_t t = 0; t < mesh.tets.size(); ++t) {
    int earliest = rank[static_cast<size_t>(mesh.tets[t][0])];
    for (const int v : mesh.tets[t]) earliest = std::min(earliest, rank[static_cast<size_t>(v)]);
    tet_rank[t] = earliest;
  }
  const auto by_rank = [&](int a, int b) {
    return tet_rank[static_cast<size_t>(a)] < tet_rank[static_cast<size_t>(b)] ||
           (tet_rank[static_cast<size_t>(a)] == tet_rank[static_cast<size_t>(b)] && a < b);
  };
  for (AssemblyPhase& phase : m_phases) {
    for (std::vector<int>& part : phase) std::sort(part.begin(), part.end(), by_rank);
  }
  std::sort(m_serial_tets.begin(), m_serial_tets.end(), by_rank);
}

void CorotationalElasticity::exclude(int tet) {
  if (tet < 0 || tet >= tet_count()) {
    throw ParameterError("CorotationalElasticity::exclude: tet " + std::to_string(tet) + " outside [0, " +
                         std::to_string(tet_count()) + ")");
  }
  const size_t k = stored(tet);
  m_excluded[k] = 1;
  m_rotations_ahead[k] = m_rotations[k];  // frozen alike in both sets from now on
  m_warm_starts_ahead[k] = m_warm_starts[k];
  m_turns_before[k] = m_warm_starts[k];
}

namespace {

// Per-tet values held by storage index, in mesh order.
template <class Value>
std::vector<Value> by_tet_id(const std::vector<Value>& stored, const std::vector<int>& tet_id) {
  std::vector<Value> by_tet(stored.size());
  for (size_t k = 0; k < stored.size(); ++k) by_tet[static_cast<size_t>(tet_id[k])] = stored[k];
  return by_tet;
}

}  // namespace

std::vector<Eigen::Matrix3d> CorotationalElasticity::rotations() const { return by_tet_id(m_rotations, m_tet_id); }

std::vector<Eigen::Quaterniond> CorotationalElasticity::warm_starts() const {
  return by_tet_id(m_warm_starts, m_tet_id);
}

std::vector<Eigen::Quaterniond> CorotationalElasticity::turns_before() const {
  return by_tet_id(m_turns_before, m_tet_id);
}

void CorotationalElasticity::restore_rotations(const std::vector<Eigen::Matrix3d>& rotations,
                                               const std::vector<Eigen::Quaterniond>& warm_starts,
                                               const std::vector<Eigen::Quaterniond>& turns_before) {
  if (rotations.size() != m_tets.size() || warm_starts.size() != m_tets.size() ||
      turns_before.size() != m_tets.size()) {
    throw std::invalid_argument(
        "co-rotational elasticity: expected one rotation, warm start and turn before per tet (" +
        std::to_string(m_tets.size()) + "), got " + std::to_string(rotations.size()) + ", " +
        std::to_string(warm_starts.size()) + " and " + std::to_string(turns_before.size()));
  }
  for (size_t t = 0; t < rotations.size(); ++t) {
    const size_t k = stored(static_cast<int>(t));
    m_rotations[k] = rotations[t];
    m_warm_starts[k] = warm_starts[t];
    m_turns_before[k] = turns_before[t];
  }
  m_rotations_ahead = m_rotations;
  m_warm_starts_ahead = m_warm_starts;
}

void CorotationalElasticity::reset_rotations() {
  std::fill(m_rotations.begin(), m_rotations.end(), Eigen::Matrix3d::Identity());
  std::fill(m_warm_starts.begin(), m_warm_starts.end(), Eigen::Quaterniond::Identity());
  m_rotations_ahead = m_rotations;
  m_warm_starts_ahead = m_warm_starts;
  m_turns_before = m_warm_starts;
}

void CorotationalElasticity::evaluate(const Eigen::VectorXd& positions_m, Eigen::VectorXd& internal_forces_n,
                                      BlockSparseMatrix* tangent, const std::vector<TetSlots>* slots, WorkTeam* team,
                                      double* elastic_energy_j, ExtractInto into) {
  assert(tangent == nullptr || (slots != nullptr && slots->size() == m_tets.size()));
  // Each part's energy apart, added in part order: bitwise the same with a team or without.
  double energy = sum_over_phases(team, static_cast<int>(m_phases.size()), [&](int phase, int part) {
    double part_energy = 0.0;
    add_tets(m_phases[static_cast<size_t>(phase)][static_cast<size_t>(part)], positions_m, internal_forces_n, tangent,
             slots, elastic_energy_j != nullptr ? &part_energy : nullptr, into);
    return part_energy;
  });
  add_tets(m_serial_tets, positions_m, internal_forces_n, tangent, slots,
           elastic_energy_j != nullptr ? &energy : nullptr, into);
  if (elastic_energy_j != nullptr) *elastic_energy_j = energy;
}

template <class TetAt, class Visit>
void CorotationalElasticity::in_rotation_batches(size_t count, TetAt tet_at, const Eigen::VectorXd& positions_m,
                                                 std::vector<Eigen::Quaterniond>* warm_starts,
                                                 std::vector<Eigen::Matrix3d>* rotations,
                                                 std::vector<Eigen::Quaterniond>* turns_before, Visit visit) const {
  std::array<size_t, ROTATION_BATCH> batch{};
  std::array<Eigen::Matrix3d, ROTATION_BATCH> gradients;
  std::array<Eigen::Quaterniond, ROTATION_BATCH> warm_start_copies;
  std::array<Eigen::Matrix3d, ROTATION_BATCH> rotation_copies;
  std::array<Eigen::Quaterniond*, ROTATION_BATCH> lane_warm_starts{};
  std::array<Eigen::Matrix3d*, ROTATION_BATCH> lane_rotations{};
  std::array<Eigen::Quaterniond*, ROTATION_BATCH> lane_turns_before{};
  size_t next = 0;
  while (next < count) {
    int lanes = 0;
    for (; next < count && lanes < ROTATION_BATCH; ++next) {
      const auto t = static_cast<size_t>(tet_at(next));
      if (m_excluded[t] != 0) continue;
      const auto lane = static_cast<size_t>(lanes++);
      batch[lane] = t;
      gradients[lane] = deformation_gradient(m_rest[t], gather(positions_m, m_tets[t]));
      if (warm_starts != nullptr) {
        if (warm_starts != &m_warm_starts) (*warm_starts)[t] = m_warm_starts[t];  // the ahead set, from the own
        lane_turns_before[lane] = &(*turns_before)[t];
        lane_warm_starts[lane] = &(*warm_starts)[t];
        lane_rotations[lane] = &(*rotations)[t];
      } else {
        warm_start_copies[lane] = m_warm_starts[t];
        lane_warm_starts[lane] = &warm_start_copies[lane];
        lane_rotations[lane] = &rotation_copies[lane];
      }
    }
    extract_rotations(
        lanes, gradients.data(), lane_warm_starts.data(), lane_rotations.data(), m_rotation_settings,
        warm_starts != nullptr ? TurnsBefore{lane_turns_before.data(), warm_starts == &m_warm_starts} : TurnsBefore{});
    for (size_t lane = 0; lane < static_cast<size_t>(lanes); ++lane) {
      visit(batch[lane], gradients[lane], *lane_rotations[lane]);
    }
  }
}

TISSUE_HOT_KERNEL void CorotationalElasticity::add_tets(const std::vector<int>& tets, const Eigen::VectorXd& positions_m,
                                                        Eigen::VectorXd& internal_forces_n, BlockSparseMatrix* tangent,
                                                        const std::vector<TetSlots>* slots, double* energy_j,
                                                        ExtractInto into) {
  double energy = 0.0;
  in_rotation_batches(
      tets.size(), [&tets](size_t k) { return tets[k]; }, positions_m,
      into == ExtractInto::ahead ? &m_warm_starts_ahead : &m_warm_starts,
      into == ExtractInto::ahead ? &m_rotations_ahead : &m_rotations, &m_turns_before,
      [&](size_t t, const Eigen::Matrix3d& f, const Eigen::Matrix3d& rotation) {
        add_tet(t, f, rotation, internal_forces_n, tangent, slots);
        if (energy_j != nullptr) energy += m_elements.energy_j(m_rest[t], rotation, f);
      });
  if (energy_j != nullptr) *energy_j += energy;
}

TISSUE_HOT_KERNEL void CorotationalElasticity::add_tet(size_t k, const Eigen::Matrix3d& f, const Eigen::Matrix3d& r,
                                                       Eigen::VectorXd& internal_forces_n, BlockSparseMatrix* tangent,
                                                       const std::vector<TetSlots>* slots) const {
  const Tet& tet = m_tets[k];
  const TetRest& rest = m_rest[k];

  // Co-rotational: f_i = V R sigma g_i (equal to R K_e (R^T x - X), see docs/DESIGN.md, "Elasticity").
  const Eigen::Matrix<double, 3, 4> forces = m_elements.forces(rest, r, f);
  for (int i = 0; i < 4; ++i) internal_forces_n.segment<3>(3 * tet[static_cast<size_t>(i)]) += forces.col(i);

  if (tangent == nullptr) return;
  const TetSlots& tet_slots = (*slots)[static_cast<size_t>(m_tet_id[k])];
  if (m_elements.model == MaterialModel::corotational_linear) {
    // Each stored block straight from the rotated shape gradients (the hot path: no 12 x 12).
    element_blocks::add_rotated_stiffness_blocks(tet_slots, *tangent, rest.shape_gradients_per_m, lame_of(rest),
                                                 rest.volume_m3, r);
    return;
  }
  std::array<Eigen::Matrix3d, 16> blocks;
  m_elements.blocks(rest, r, f, blocks);
  element_blocks::add_blocks(tet_slots, *tangent, [&](int i, int j) { return blocks[static_cast<size_t>(4 * i + j)]; });
}

TISSUE_HOT_KERNEL double CorotationalElasticity::energy_of(const std::vector<int>& tets,
                                                             const Eigen::VectorXd& positions_m) const {
  // Rotations in SIMD lanes as in a step, from copies of the warm starts; the terms added in the
  // list's order, as add_tets adds them.
  double energy = 0.0;
  in_rotation_batches(
      tets.size(), [&tets](size_t k) { return tets[k]; }, positions_m, nullptr, nullptr, nullptr,
      [&](size_t t, const Eigen::Matrix3d& f, const Eigen::Matrix3d& rotation) {
        energy += m_elements.energy_j(m_rest[t], rotation, f);
      });
  return energy;
}

// The sum evaluate() makes, in its order (each phase's parts apart, added in part order, then the
// serial tets): the energy guard reads the same potential whichever pass found it, and a step kept
// from the guard's evaluation continues as one evaluated anew after a restore (backward_euler.cpp).
double CorotationalElasticity::elastic_energy_j(const Eigen::VectorXd& positions_m, WorkTeam* team) const {
  const double phased = sum_over_phases(team, static_cast<int>(m_phases.size()), [&](int phase, int part) {
    return energy_of(m_phases[static_cast<size_t>(phase)][static_cast<size_t>(part)], positions_m);
  });
  return phased + energy_of(m_serial_tets, positions_m);
}

std::vector<double> lumped_vertex_sums(const TetMesh& mesh, std::span<const double> per_region_per_m3) {
  if (per_region_per_m3.size() < static_cast<size_t>(mesh.region_count())) {
    throw std::invalid_argument("lumped_vertex_sums: " + std::to_string(per_region_per_m3.size()) + " values for " +
                                std::to_string(mesh.region_count()) + " regions");
  }
  std::vector<double> sums(static_cast<size_t>(mesh.vertex_count()), 0.0);
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets[static_cast<size_t>(t)];
    const auto& p = mesh.rest_positions_m;
    const double per_m3 = per_region_per_m3[static_cast<size_t>(mesh.region_of(t))];
    const double quarter = 0.25 * per_m3 *
                           signed_tet_volume(p[static_cast<size_t>(tet[0])], p[static_cast<size_t>(tet[1])],
                                             p[static_cast<size_t>(tet[2])], p[static_cast<size_t>(tet[3])]);
    for (int v : tet) sums[static_cast<size_t>(v)] += quarter;
  }
  return sums;
}

std::vector<double> lumped_vertex_masses(const TetMesh& mesh, const std::vector<Material>& materials) {
  std::vector<double> densities_kg_per_m3;
  for (const Material& material : materials) densities_kg_per_m3.push_back(material.density_kg_per_m3);
  return lumped_vertex_sums(mesh, densities_kg_per_m3);
}

}  // namespace tissue
