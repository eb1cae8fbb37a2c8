// DeformableBody: scatter the unknowns to vertex positions, evaluate the FEM (uncut tets, cut
// tets, point spring), gather forces back; grow the system in place when tets are cut.
//
// Enriched lumped mass and gravity (DESIGN section 4; eq. 4.16 is garbled). Lumping each part of a
// cut tet as a full tet of mass w_p m gives the kinetic energy
//   (m/4) sum_j [w_a |v_j + Psi_aj da_j|^2 + w_b |v_j + Psi_bj da_j|^2]
// and, for a vertex with H_j = +1 (Psi_aj = 0, Psi_bj = -1), the mass blocks M^uu = m/4,
// M^ua = -w_b m/4, M^aa = w_b m/4 (for H_j = -1: m/4, +w_a m/4, w_a m/4). The diagonal lumping
// keeps M^uu (unchanged by the cut: total mass conserved) and M^aa = rho V_opposite(j) / 4, the mass
// of the part on the other side of the cut, and drops M^ua. Gravity is the derivative of the same
// lumped potential -sum_p (w_p m/4) g . p_pj: on u_j it stays m/4 g, on a_j it is
//   Psi_opposite(j) rho V_opposite(j) / 4 g,   Psi_opposite(j) = -H_j,
// i.e. -w_b m/4 g for a vertex above the cut and +w_a m/4 g for one below: pulling the ghost copy
// (which belongs to the other part, at x_j + Psi_opposite a_j) down. With it the statics are exact
// (the load of each part sits on that part). The dropped M^ua makes the dynamics of a piece cut
// free inexact: translating the piece moves both u_j and a_j of its real vertices next to the cut,
// so it carries an extra inertia 2 sum M^aa over those vertices (quantified in tests/unit/xfem).
#include "core/fem/deformable_body.hpp"

#include "core/system/hot_kernel.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {
namespace {

BodySettings checked(BodySettings settings, int vertex_count) {
  validate(settings.material);
  validate(settings.damping);
  validate(settings.rotation);
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

// Per vertex: how many vertices share a tet with it (itself included), all and free ones.
struct Neighbourhoods {
  std::vector<int> all;
  std::vector<int> free;
};

Neighbourhoods neighbourhoods(const TetMesh& mesh, const DofMap& dofs) {
  std::vector<std::vector<int>> near(static_cast<size_t>(mesh.vertex_count()));
  for (const Tet& tet : mesh.tets) {
    for (const int a : tet)
      near[static_cast<size_t>(a)].insert(near[static_cast<size_t>(a)].end(), tet.begin(), tet.end());
  }
  Neighbourhoods counts{std::vector<int>(near.size()), std::vector<int>(near.size())};
  for (size_t v = 0; v < near.size(); ++v) {
    std::sort(near[v].begin(), near[v].end());
    near[v].erase(std::unique(near[v].begin(), near[v].end()), near[v].end());
    counts.all[v] = static_cast<int>(near[v].size());
    counts.free[v] = static_cast<int>(std::count_if(
        near[v].begin(), near[v].end(), [&](int w) { return dofs.vertex_row[static_cast<size_t>(w)] >= 0; }));
  }
  return counts;
}

// Room one cut can ever need, so that cutting never overflows a row (DESIGN section 3: the matrix
// grows in place). A u row holds its free neighbours and gains one u-a block per enriched
// neighbour, fixed ones included: free + all (twice its blocks inside the body, more next to fixed
// vertices). An enriched row holds a-u blocks with the free neighbours and a-a blocks with all.
std::vector<int> u_row_capacities(const TetMesh& mesh, const DofMap& dofs) {
  const Neighbourhoods counts = neighbourhoods(mesh, dofs);
  std::vector<int> capacities(static_cast<size_t>(dofs.free_vertex_count()));
  for (size_t row = 0; row < capacities.size(); ++row) {
    const auto v = static_cast<size_t>(dofs.row_vertex[row]);
    capacities[row] = counts.free[v] + counts.all[v];
  }
  return capacities;
}

std::vector<int> enriched_row_capacities(const TetMesh& mesh, const DofMap& dofs) {
  const Neighbourhoods counts = neighbourhoods(mesh, dofs);
  std::vector<int> capacities(counts.all.size());
  for (size_t v = 0; v < capacities.size(); ++v) capacities[v] = counts.free[v] + counts.all[v];
  return capacities;
}

}  // namespace

DeformableBody::DeformableBody(TetMesh mesh, BodySettings settings)
    : m_mesh(std::move(mesh)),
      m_settings(checked(std::move(settings), m_mesh.vertex_count())),
      m_dofs(make_dof_map(m_mesh.vertex_count(), m_settings.fixed_vertices)),
      m_elasticity(m_mesh, m_settings.material, m_settings.rotation),
      m_vertex_mass_kg(lumped_vertex_masses(m_mesh, m_settings.material.density_kg_per_m3)),
      m_tangent(stiffness_pattern(m_mesh, m_dofs), m_settings.reserve, u_row_capacities(m_mesh, m_dofs)),
      m_slots(make_tet_slots(m_mesh, m_dofs, m_tangent)),
      m_xfem(m_elasticity.lame(), m_settings.rotation),
      m_enriched_row_capacity(enriched_row_capacities(m_mesh, m_dofs)),
      m_first_enriched_dof(static_cast<size_t>(m_mesh.vertex_count()), -1),
      m_cut_index(static_cast<size_t>(m_mesh.tet_count()), -1) {
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
  // Room for the enrichments the matrix has room for (the dissertation's 150% DOFs).
  const int spare_rows = m_tangent.block_row_capacity() - m_tangent.block_rows();
  m_enriched_dofs.reserve(static_cast<size_t>(spare_rows));
  m_next_enriched_dof.reserve(static_cast<size_t>(spare_rows));
  m_xfem.reserve(std::min(m_mesh.tet_count(), 2 * spare_rows));
  for (int t = 0; t < m_mesh.tet_count(); ++t) {
    m_largest_shape_gradient_per_m =
        std::max(m_largest_shape_gradient_per_m, m_elasticity.rest(t).shape_gradients_per_m.colwise().norm().maxCoeff());
  }
}

namespace {

// |axial vector of skew(R^T G)|, G = sum_i du_i grad(phi_i)^T: the angle a displacement increment
// du turns a tet of rotation R (to first order).
double turn_angle_rad(const TetRest& rest, const Eigen::Matrix3d& rotation, const TetPositions& increment_m) {
  const Eigen::Matrix3d w = rotation.transpose() * deformation_gradient(rest, increment_m);
  return 0.5 * Eigen::Vector3d(w(2, 1) - w(1, 2), w(0, 2) - w(2, 0), w(1, 0) - w(0, 1)).norm();
}

}  // namespace

const std::vector<Eigen::Matrix3d>* DeformableBody::block_frames() const {
  // A vertex's frame: the rotation nearest the sum of its uncut tets' rotations (their mean turn),
  // found from the first one's, so it depends on the rotations alone (no history).
  const size_t vertices = static_cast<size_t>(m_mesh.vertex_count());
  m_vertex_frames.assign(vertices, Eigen::Matrix3d::Zero());
  m_vertex_first_tet.assign(vertices, -1);
  for (int t = 0; t < m_elasticity.tet_count(); ++t) {
    if (m_elasticity.is_excluded(t)) continue;
    for (const int v : m_mesh.tets[static_cast<size_t>(t)]) {
      m_vertex_frames[static_cast<size_t>(v)] += m_elasticity.rotation(t);
      if (m_vertex_first_tet[static_cast<size_t>(v)] < 0) m_vertex_first_tet[static_cast<size_t>(v)] = t;
    }
  }
  for (size_t v = 0; v < vertices; ++v) {
    const int first = m_vertex_first_tet[v];
    if (first < 0) {
      m_vertex_frames[v].setIdentity();
      continue;
    }
    Eigen::Quaterniond start(m_elasticity.rotation(first));
    m_vertex_frames[v] = extract_rotation(m_vertex_frames[v], start, m_settings.rotation);
  }
  m_block_frames.resize(static_cast<size_t>(m_tangent.block_rows()));
  for (int row = 0; row < m_dofs.free_vertex_count(); ++row) {
    m_block_frames[static_cast<size_t>(row)] = m_vertex_frames[static_cast<size_t>(m_dofs.row_vertex[static_cast<size_t>(row)])];
  }
  // An enriched unknown moves the part of a cut tet beyond its vertex; it takes the vertex's frame.
  for (const EnrichedDof& dof : m_enriched_dofs) {
    m_block_frames[static_cast<size_t>(dof.row)] = m_vertex_frames[static_cast<size_t>(dof.vertex)];
  }
  return &m_block_frames;
}

double DeformableBody::largest_turn_rad(const Eigen::VectorXd& increment_m, double resolution_rad) const {
  if (increment_m.size() != dof_count()) {
    throw std::invalid_argument("largest_turn_rad: the increment has " + std::to_string(increment_m.size()) +
                                " entries, the body " + std::to_string(dof_count()) + " unknowns");
  }
  double largest_block_m = 0.0;
  for (Eigen::Index row = 0; row < increment_m.size() / 3; ++row) {
    largest_block_m = std::max(largest_block_m, increment_m.segment<3>(3 * row).norm());
  }
  // G = sum_{i>0} (dp_i - dp_0) grad(phi_i)^T with |dp_i - dp_0| <= 4 max|block| (a part's vertex
  // moves by du + Psi da), so the angle is at most |G| <= 12 max|block| max|grad(phi)|.
  const double bound_rad = 12.0 * largest_block_m * m_largest_shape_gradient_per_m;
  if (bound_rad <= resolution_rad) return bound_rad;
  return largest_element_turn_rad(increment_m);
}

// (A hot kernel: GCC cannot clone the virtual largest_turn_rad itself.)
TISSUE_HOT_KERNEL double DeformableBody::largest_element_turn_rad(const Eigen::VectorXd& increment_m) const {
  const auto vertex_increment = [&](int vertex) -> Eigen::Vector3d {
    const int row = vertex_block_row(vertex);
    return row < 0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(increment_m.segment<3>(3 * row));
  };
  double largest_rad = 0.0;
  TetPositions increment;
  for (int t = 0; t < m_mesh.tet_count(); ++t) {
    if (m_cut_index[static_cast<size_t>(t)] >= 0) continue;
    const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
    for (size_t j = 0; j < 4; ++j) increment[j] = vertex_increment(tet[j]);
    largest_rad = std::max(largest_rad, turn_angle_rad(m_elasticity.rest(t), m_elasticity.rotation(t), increment));
  }
  for (int k = 0; k < m_xfem.cut_tet_count(); ++k) {
    const CutTet& cut_tet = m_xfem.cut_tets()[static_cast<size_t>(k)];
    for (const CutPart part : {CutPart::above, CutPart::below}) {
      for (size_t j = 0; j < 4; ++j) {
        increment[j] = vertex_increment(cut_tet.vertices[j]) +
                       cut_tet.shift(static_cast<int>(j), part) *
                           Eigen::Vector3d(increment_m.segment<3>(3 * cut_tet.enriched_row[j]));
      }
      largest_rad = std::max(largest_rad, turn_angle_rad(m_xfem.rest(k), m_xfem.rotation(k, part), increment));
    }
  }
  return largest_rad;
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

void DeformableBody::check_unknowns(const Eigen::VectorXd& displacement_m) const {
  if (displacement_m.size() != dof_count()) {
    throw std::invalid_argument("DeformableBody: displacement has " + std::to_string(displacement_m.size()) +
                                " unknowns, the body has " + std::to_string(dof_count()) +
                                " (grow the state after enrich())");
  }
}

void DeformableBody::evaluate(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n,
                              bool update_tangent) {
  check_unknowns(displacement_m);
  positions(displacement_m, m_positions_m);
  m_vertex_forces_n.setZero();
  if (update_tangent) m_tangent.set_zero();
  BlockSparseMatrix* tangent = update_tangent ? &m_tangent : nullptr;
  m_elasticity.evaluate(m_positions_m, m_vertex_forces_n, tangent, &m_slots, m_team);
  internal_force_n.resize(dof_count());
  const int u_rows = m_dofs.free_vertex_count();
  internal_force_n.tail(3 * enriched_dof_count()).setZero();
  m_xfem.evaluate(m_positions_m, displacement_m, m_vertex_forces_n, internal_force_n, tangent);

  for (ForceTerm* term : m_force_terms) {
    term->add_force(m_positions_m, m_vertex_forces_n);
    if (tangent != nullptr) term->add_tangent(*tangent);
  }

  for (int row = 0; row < u_rows; ++row) {
    internal_force_n.segment<3>(3 * row) =
        m_vertex_forces_n.segment<3>(3 * m_dofs.row_vertex[static_cast<size_t>(row)]);
  }
}

double DeformableBody::elastic_energy_j(const Eigen::VectorXd& displacement_m) {
  check_unknowns(displacement_m);
  positions(displacement_m, m_positions_m);
  return m_elasticity.elastic_energy_j(m_positions_m) + m_xfem.elastic_energy_j(m_positions_m, displacement_m);
}

double DeformableBody::potential_energy_j(const Eigen::VectorXd& displacement_m) {
  double energy = elastic_energy_j(displacement_m) - m_external_force_n.dot(displacement_m);  // positions set
  for (const ForceTerm* term : m_force_terms) energy += term->energy_j(m_positions_m);
  return energy;
}

double DeformableBody::kinetic_energy_j(const Eigen::VectorXd& velocity_m_per_s) const {
  return 0.5 * velocity_m_per_s.dot(m_mass_kg.cwiseProduct(velocity_m_per_s));
}

void DeformableBody::save_rotations(Rotations& rotations) const {
  rotations.tets = m_elasticity.rotations();
  rotations.tet_warm_starts = m_elasticity.warm_starts();
  rotations.parts = m_xfem.rotations();
  rotations.part_warm_starts = m_xfem.warm_starts();
}

void DeformableBody::restore_rotations(const Rotations& rotations) {
  if (rotations.parts.size() != m_xfem.cut_tets().size() ||
      rotations.part_warm_starts.size() != m_xfem.cut_tets().size()) {
    throw std::invalid_argument("body: the saved rotations are of " + std::to_string(rotations.parts.size()) +
                                " cut tets, the body has " + std::to_string(m_xfem.cut_tets().size()));
  }
  m_elasticity.restore_rotations(rotations.tets, rotations.tet_warm_starts);
  m_xfem.restore_rotations(rotations.parts, rotations.part_warm_starts);
}

void DeformableBody::reset_rotations() {
  m_elasticity.reset_rotations();
  m_xfem.reset_rotations();
}

// --- XFEM ---

int DeformableBody::find_enriched_dof(int vertex, int cut_id, int side) const {
  if (vertex < 0 || vertex >= m_mesh.vertex_count()) return -1;
  for (int k = m_first_enriched_dof[static_cast<size_t>(vertex)]; k >= 0;
       k = m_next_enriched_dof[static_cast<size_t>(k)]) {
    const EnrichedDof& dof = m_enriched_dofs[static_cast<size_t>(k)];
    if (dof.cut_id == cut_id && dof.side == side) return k;
  }
  return -1;
}

void DeformableBody::check_cuts(std::span<const TetCut> cuts) const {
  std::vector<int> tets;
  tets.reserve(cuts.size());
  for (size_t c = 0; c < cuts.size(); ++c) {
    const TetCut& cut = cuts[c];
    const std::string where = "enrich: cut " + std::to_string(c) + " (tet " + std::to_string(cut.tet) + "): ";
    if (cut.tet < 0 || cut.tet >= m_mesh.tet_count()) {
      throw ParameterError(where + "tet outside [0, " + std::to_string(m_mesh.tet_count()) + ")");
    }
    if (cut_tet_index(cut.tet) >= 0) throw ParameterError(where + "the tet is cut already (one cut per tet)");
    bool above = false;
    bool below = false;
    for (const std::int8_t side : cut.side) {
      if (side != 1 && side != -1) throw ParameterError(where + "a vertex side is neither +1 nor -1");
      above = above || side == 1;
      below = below || side == -1;
    }
    if (!above || !below) throw ParameterError(where + "all vertices on one side: the tet is not cut");
    if (!std::isfinite(cut.volume_fraction_above) || !(cut.volume_fraction_above > 0.0) ||
        !(cut.volume_fraction_above < 1.0)) {
      throw ParameterError(where + "volume fraction " + std::to_string(cut.volume_fraction_above) +
                           " is not in (0, 1)");
    }
    tets.push_back(cut.tet);
  }
  std::sort(tets.begin(), tets.end());
  const auto twice = std::adjacent_find(tets.begin(), tets.end());
  if (twice != tets.end()) throw ParameterError("enrich: tet " + std::to_string(*twice) + " is cut twice in one batch");
}

EnrichmentResult DeformableBody::enrich(std::span<const TetCut> cuts, DynamicState& state) {
  const Eigen::Index size = dof_count();
  if (state.displacement_m.size() != size || state.velocity_m_per_s.size() != size) {
    throw std::invalid_argument("enrich: the state has " + std::to_string(state.displacement_m.size()) +
                                " displacements and " + std::to_string(state.velocity_m_per_s.size()) +
                                " velocities, the body " + std::to_string(size) + " unknowns");
  }
  check_cuts(cuts);
  // The offsets: the current a of each existing unknown a cut tet will join.
  std::vector<TetPositions> offsets_m(cuts.size());
  for (size_t c = 0; c < cuts.size(); ++c) {
    const Tet& tet = m_mesh.tets[static_cast<size_t>(cuts[c].tet)];
    for (size_t i = 0; i < 4; ++i) {
      const int k = find_enriched_dof(tet[i], cuts[c].cut_id, cuts[c].side[i]);
      offsets_m[c][i] = k < 0 ? Eigen::Vector3d::Zero()
                              : Eigen::Vector3d(state.displacement_m.segment<3>(3 * m_enriched_dofs[static_cast<size_t>(k)].row));
    }
  }
  const Eigen::VectorXd mass_before_kg = m_mass_kg;
  const EnrichmentResult result = enrich(cuts, offsets_m);
  grow_state(state);
  // An existing unknown that gained mass keeps its momentum (an inelastic join of the new part).
  for (Eigen::Index r = 0; r < mass_before_kg.size(); ++r) {
    if (m_mass_kg(r) > mass_before_kg(r)) state.velocity_m_per_s(r) *= mass_before_kg(r) / m_mass_kg(r);
  }
  return result;
}

EnrichmentResult DeformableBody::enrich(std::span<const TetCut> cuts, std::span<const TetPositions> offsets_m) {
  check_cuts(cuts);
  if (!offsets_m.empty() && offsets_m.size() != cuts.size()) {
    throw ParameterError("enrich: " + std::to_string(offsets_m.size()) + " offsets for " +
                         std::to_string(cuts.size()) + " cuts");
  }
  for (const TetPositions& offsets : offsets_m) {
    for (const Eigen::Vector3d& offset : offsets) {
      if (!offset.allFinite()) throw ParameterError("enrich: an enrichment offset is not finite");
    }
  }
  EnrichmentResult result;
  const std::uint64_t layout_before = m_tangent.layout_revision();
  const int u_rows = m_dofs.free_vertex_count();
  const int old_dofs = enriched_dof_count();

  // 1. The enriched unknowns: one per (vertex, cut id, side), appended as block rows.
  std::vector<std::array<int, 4>> dof_of_cut(cuts.size());
  for (size_t c = 0; c < cuts.size(); ++c) {
    const TetCut& cut = cuts[c];
    const Tet& tet = m_mesh.tets[static_cast<size_t>(cut.tet)];
    for (size_t i = 0; i < 4; ++i) {
      int k = find_enriched_dof(tet[i], cut.cut_id, cut.side[i]);
      if (k < 0) {
        k = enriched_dof_count();
        const int row = m_tangent.append_block_row(m_enriched_row_capacity[static_cast<size_t>(tet[i])]);
        if (row != u_rows + k) throw std::logic_error("enrich: the tangent's rows and the unknowns disagree");
        m_enriched_dofs.push_back(EnrichedDof{tet[i], cut.cut_id, cut.side[i], row});
        m_next_enriched_dof.push_back(m_first_enriched_dof[static_cast<size_t>(tet[i])]);
        m_first_enriched_dof[static_cast<size_t>(tet[i])] = k;
      }
      dof_of_cut[c][i] = k;
    }
  }
  result.new_enriched_dofs = enriched_dof_count() - old_dofs;

  // 2. Mass and external force of the new unknowns start at zero, then each cut tet adds its share.
  m_mass_kg.conservativeResize(dof_count());
  m_external_force_n.conservativeResize(dof_count());
  m_mass_kg.tail(3 * result.new_enriched_dofs).setZero();
  m_external_force_n.tail(3 * result.new_enriched_dofs).setZero();

  const double density = m_settings.material.density_kg_per_m3;
  for (size_t c = 0; c < cuts.size(); ++c) {
    const TetCut& cut = cuts[c];
    CutTet cut_tet;
    cut_tet.cut = cut;
    cut_tet.vertices = m_mesh.tets[static_cast<size_t>(cut.tet)];
    cut_tet.weight_above = cut.volume_fraction_above;
    cut_tet.weight_below = 1.0 - cut.volume_fraction_above;
    for (size_t i = 0; i < 4; ++i) cut_tet.enriched_row[i] = m_enriched_dofs[static_cast<size_t>(dof_of_cut[c][i])].row;
    if (!offsets_m.empty()) cut_tet.enrichment_offset_m = offsets_m[c];

    const TetRest& rest = m_elasticity.rest(cut.tet);
    for (size_t i = 0; i < 4; ++i) {
      // The part on the other side of the cut from vertex i, and Psi of vertex i in it (= -H_i).
      const CutPart opposite = cut.side[i] == 1 ? CutPart::below : CutPart::above;
      const double quarter_mass_kg = 0.25 * density * cut_tet.weight(opposite) * rest.volume_m3;
      const int row = cut_tet.enriched_row[i];
      m_mass_kg.segment<3>(3 * row).array() += quarter_mass_kg;
      m_external_force_n.segment<3>(3 * row) +=
          cut_tet.shift(static_cast<int>(i), opposite) * quarter_mass_kg * m_settings.gravity_m_per_s2;
    }

    m_elasticity.exclude(cut.tet);
    const int k = m_xfem.cut_tet_count();
    m_cut_index[static_cast<size_t>(cut.tet)] = k;
    m_xfem.add(cut_tet, rest, m_elasticity.rotation(cut.tet));

    // 3. The blocks its pieces couple beyond u-u (which exist already), into the reserved room.
    const int dofs = m_xfem.dof_count(k);
    for (int r = 0; r < dofs; ++r) {
      for (int col = 0; col < dofs; ++col) {
        if (r < 4 && col < 4) continue;
        if (!m_xfem.couples(k, r, col)) continue;  // identically zero
        const int row = cut_tet_dof_row(k, r);
        const int column = cut_tet_dof_row(k, col);
        if (row < 0 || column < 0) continue;  // a fixed vertex's u
        m_tangent.insert_block(row, column);
      }
    }
  }
  result.new_cut_tets = static_cast<int>(cuts.size());

  // 4. Slots: of the new cut tets only, unless the storage moved (rare: room is reserved ahead).
  result.matrix_relayout = m_tangent.layout_revision() != layout_before;
  if (result.matrix_relayout) {
    refresh_all_slots();
  } else {
    for (int k = m_xfem.cut_tet_count() - result.new_cut_tets; k < m_xfem.cut_tet_count(); ++k)
      refresh_cut_tet_slots(k);
  }
  return result;
}

int DeformableBody::cut_tet_dof_row(int cut_tet_index, int dof) const {
  if (dof < 4) {
    return vertex_block_row(m_xfem.cut_tets()[static_cast<size_t>(cut_tet_index)].vertices[static_cast<size_t>(dof)]);
  }
  return m_xfem.ghost_rows(cut_tet_index)[static_cast<size_t>(dof - 4)];
}

void DeformableBody::refresh_cut_tet_slots(int cut_tet_index) {
  const CutTet& cut_tet = m_xfem.cut_tets()[static_cast<size_t>(cut_tet_index)];
  const int dofs = m_xfem.dof_count(cut_tet_index);
  const auto row_of = [&](int dof) { return cut_tet_dof_row(cut_tet_index, dof); };
  const CutTetSlots slots = m_xfem.slots(cut_tet_index);
  for (int r = 0; r < dofs; ++r) {
    for (int col = 0; col < dofs; ++col) {
      int slot = -1;
      if (m_xfem.couples(cut_tet_index, r, col) && row_of(r) >= 0 && row_of(col) >= 0) {
        slot = m_tangent.find_slot(row_of(r), row_of(col));
        if (slot < 0)
          throw std::logic_error("enrich: a block of cut tet " + std::to_string(cut_tet.cut.tet) + " is missing");
      }
      slots[static_cast<size_t>(dofs * r + col)] = slot;
    }
  }
}

void DeformableBody::refresh_all_slots() {
  m_slots = make_tet_slots(m_mesh, m_dofs, m_tangent);
  for (int k = 0; k < m_xfem.cut_tet_count(); ++k) refresh_cut_tet_slots(k);
  for (ForceTerm* term : m_force_terms) term->locate(term_layout());
}

void DeformableBody::grow_state(DynamicState& state) const {
  const Eigen::Index old_size = state.displacement_m.size();
  if (old_size > dof_count() || state.velocity_m_per_s.size() != old_size) {
    throw std::invalid_argument("grow_state: the state has " + std::to_string(old_size) + " displacements and " +
                                std::to_string(state.velocity_m_per_s.size()) + " velocities, the body " +
                                std::to_string(dof_count()) + " unknowns");
  }
  state.displacement_m.conservativeResize(dof_count());
  state.velocity_m_per_s.conservativeResize(dof_count());
  state.displacement_m.tail(dof_count() - old_size).setZero();
  state.velocity_m_per_s.tail(dof_count() - old_size).setZero();
}

TetPositions DeformableBody::part_positions(const Eigen::VectorXd& displacement_m, int cut_tet_index,
                                            CutPart part) const {
  const CutTet& cut_tet = m_xfem.cut_tets().at(static_cast<size_t>(cut_tet_index));
  TetPositions real_m;
  for (size_t j = 0; j < 4; ++j) {
    const int vertex = cut_tet.vertices[j];
    const int row = vertex_block_row(vertex);
    real_m[j] = m_mesh.rest_positions_m[static_cast<size_t>(vertex)];
    if (row >= 0) real_m[j] += displacement_m.segment<3>(3 * row);
  }
  return piece_positions(m_xfem.piece(cut_tet_index, part == CutPart::above ? 0 : 1), real_m, displacement_m);
}

double DeformableBody::part_mass_kg(int cut_tet_index, CutPart part) const {
  const size_t k = static_cast<size_t>(cut_tet_index);
  return m_settings.material.density_kg_per_m3 * m_xfem.cut_tets().at(k).weight(part) *
         m_xfem.rest(cut_tet_index).volume_m3;
}

// --- Force terms ---

void DeformableBody::attach(ForceTerm& term) {
  if (std::find(m_force_terms.begin(), m_force_terms.end(), &term) == m_force_terms.end()) {
    m_force_terms.push_back(&term);
  }
  term.locate(term_layout());
}

void DeformableBody::detach(ForceTerm& term) { std::erase(m_force_terms, &term); }

}  // namespace tissue
