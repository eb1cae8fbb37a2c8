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

#include "core/mesh/topology.hpp"
#include "core/system/hot_kernel.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>
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

// Room cuts need, so that cutting does not overflow a row (DESIGN section 3: the matrix grows in
// place). A u row holds its free neighbours and gains a u-a block for every ghost of a neighbour,
// fixed ones included: one per neighbour for a single cut, up to three where two cuts cross (the
// ghosts behind the first, the second and both): free + GHOSTS_PER_NEIGHBOUR all. An enriched row
// holds a-u blocks with the free neighbours and a-a blocks with their ghosts, as many.
constexpr int GHOSTS_PER_NEIGHBOUR = 3;

std::vector<int> enriched_row_capacities(const TetMesh& mesh, const DofMap& dofs) {
  const Neighbourhoods counts = neighbourhoods(mesh, dofs);
  std::vector<int> capacities(counts.all.size());
  for (size_t v = 0; v < capacities.size(); ++v) capacities[v] = counts.free[v] + GHOSTS_PER_NEIGHBOUR * counts.all[v];
  return capacities;
}

// The reserve with spare rows of an enriched row's mean room (unless the settings give one), so
// that a cut's new rows come from the pool.
MatrixReserve with_ghost_room(MatrixReserve reserve, const TetMesh& mesh, const DofMap& dofs) {
  if (reserve.spare_row_capacity > 0 || mesh.vertex_count() == 0) return reserve;
  const std::vector<int> room = enriched_row_capacities(mesh, dofs);
  long total = 0;
  for (const int r : room) total += r;
  reserve.spare_row_capacity = static_cast<int>((total + mesh.vertex_count() - 1) / mesh.vertex_count());
  return reserve;
}

// Each region's mass damping alpha: its material's own, else the body's.
std::vector<double> region_mass_damping(const std::vector<Material>& materials, const RayleighDamping& body) {
  std::vector<double> alphas_per_s;
  for (const Material& material : materials) {
    alphas_per_s.push_back(material.mass_damping_per_s.value_or(body.mass_damping_per_s));
  }
  return alphas_per_s;
}

// alpha m per vertex, lumped as the mass is: each tet gives alpha rho V / 4 with its region's.
std::vector<double> lumped_vertex_mass_damping(const TetMesh& mesh, const std::vector<Material>& materials,
                                               const std::vector<double>& region_alpha_per_s) {
  std::vector<double> per_m3;
  for (size_t r = 0; r < materials.size(); ++r) {
    per_m3.push_back(region_alpha_per_s[r] * materials[r].density_kg_per_m3);
  }
  return lumped_vertex_sums(mesh, per_m3);
}

}  // namespace

DeformableBody::DeformableBody(TetMesh mesh, BodySettings settings)
    : m_mesh(std::move(mesh)),
      m_adjacency(build_adjacency(m_mesh)),
      m_vertex_order(locality_order(m_adjacency, m_mesh.vertex_count())),
      m_settings(checked(std::move(settings), m_mesh.vertex_count())),
      m_materials(resolve_region_materials(m_mesh.regions, m_settings.material, m_settings.region_materials)),
      m_region_mass_damping_per_s(region_mass_damping(m_materials, m_settings.damping)),
      m_dofs(make_dof_map(m_mesh.vertex_count(), m_settings.fixed_vertices, m_vertex_order)),
      m_elasticity(m_mesh, m_materials, m_settings.rotation, m_vertex_order, m_settings.material_model),
      m_vertex_mass_kg(lumped_vertex_masses(m_mesh, m_materials)),
      m_vertex_mass_damping_kg_per_s(lumped_vertex_mass_damping(m_mesh, m_materials, m_region_mass_damping_per_s)),
      m_tangent(stiffness_pattern(m_mesh, m_dofs), with_ghost_room(m_settings.reserve, m_mesh, m_dofs)),
      m_slots(make_tet_slots(m_mesh, m_dofs, m_tangent)),
      m_xfem(m_elasticity.elements(), m_settings.rotation),
      m_enriched_row_capacity(enriched_row_capacities(m_mesh, m_dofs)),
      m_first_enriched_dof(static_cast<size_t>(m_mesh.vertex_count()), -1),
      m_cut_index(static_cast<size_t>(m_mesh.tet_count()), -1) {
  const int rows = m_dofs.free_vertex_count();
  m_mass_kg.resize(3 * rows);
  m_mass_damping_kg_per_s.resize(3 * rows);
  m_external_force_n.resize(3 * rows);
  for (int row = 0; row < rows; ++row) {
    const auto vertex = static_cast<size_t>(m_dofs.row_vertex[static_cast<size_t>(row)]);
    const double mass = m_vertex_mass_kg[vertex];
    m_mass_kg.segment<3>(3 * row).setConstant(mass);
    m_mass_damping_kg_per_s.segment<3>(3 * row).setConstant(m_vertex_mass_damping_kg_per_s[vertex]);
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
  // The uncut tets (those the co-rotational model has not handed to XFEM) in halves of its storage
  // order, which streams its per-tet data, side by side with a team (a maximum: the same in any order).
  std::array<double, MAX_STEP_THREADS> largest_of_part{};
  const int parts = team_parts(m_team);
  run_parts(m_team, parts, [&](int member) {
    TetPositions increment;
    double largest = 0.0;
    const auto tets = static_cast<size_t>(m_elasticity.tet_count());
    m_elasticity.for_each_included(
        tets * static_cast<size_t>(member) / static_cast<size_t>(parts),
        tets * static_cast<size_t>(member + 1) / static_cast<size_t>(parts),
        [&](const Tet& tet, const TetRest& rest, const Eigen::Matrix3d& rotation) {
          for (size_t j = 0; j < 4; ++j) increment[j] = vertex_increment(tet[j]);
          largest = std::max(largest, turn_angle_rad(rest, rotation, increment));
        });
    largest_of_part[static_cast<size_t>(member)] = largest;
  });
  double largest_rad = *std::max_element(largest_of_part.begin(), largest_of_part.end());
  TetPositions increment;
  for (int k = 0; k < m_xfem.cut_tet_count(); ++k) {
    if (m_xfem.retired(k)) continue;
    const CutTet& cut_tet = m_xfem.cut_tets()[static_cast<size_t>(k)];
    for (int p = 0; p < static_cast<int>(m_xfem.piece_count(k)); ++p) {
      const CutPiece& piece = m_xfem.piece(k, p);
      for (size_t j = 0; j < 4; ++j) {
        increment[j] = vertex_increment(cut_tet.vertices[j]);
        if (piece.ghost_row[j] >= 0) {
          increment[j] += piece.ghost_sign[j] * Eigen::Vector3d(increment_m.segment<3>(3 * piece.ghost_row[j]));
        }
      }
      largest_rad = std::max(largest_rad, turn_angle_rad(m_xfem.rest(k), m_xfem.rotation(k, p), increment));
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
  if (update_tangent) m_tangent.set_zero(m_team);
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
  return m_elasticity.elastic_energy_j(m_positions_m, m_team) + m_xfem.elastic_energy_j(m_positions_m, displacement_m);
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
  rotations.pieces = m_xfem.piece_rotations();
  rotations.piece_warm_starts = m_xfem.piece_warm_starts();
}

void DeformableBody::restore_rotations(const Rotations& rotations) {
  if (rotations.pieces.size() != m_xfem.piece_rotations().size() ||
      rotations.piece_warm_starts.size() != m_xfem.piece_warm_starts().size()) {
    throw std::invalid_argument("body: the saved rotations are of " + std::to_string(rotations.pieces.size()) +
                                " cut-tet pieces, the body has " + std::to_string(m_xfem.piece_rotations().size()));
  }
  m_elasticity.restore_rotations(rotations.tets, rotations.tet_warm_starts);
  m_xfem.restore_rotations(rotations.pieces, rotations.piece_warm_starts);
}

void DeformableBody::reset_rotations() {
  m_elasticity.reset_rotations();
  m_xfem.reset_rotations();
}

// --- XFEM ---

int DeformableBody::find_ghost(int vertex, const SeparatingCuts& cuts) const {
  if (vertex < 0 || vertex >= m_mesh.vertex_count()) return -1;
  for (int k = m_first_enriched_dof[static_cast<size_t>(vertex)]; k >= 0;
       k = m_next_enriched_dof[static_cast<size_t>(k)]) {
    if (m_enriched_dofs[static_cast<size_t>(k)].separated_by == cuts) return k;
  }
  return -1;
}

int DeformableBody::find_enriched_dof(int vertex, int cut_id, int side) const {
  SeparatingCuts cuts;
  cuts.count = 1;
  cuts.cut_id[0] = cut_id;
  cuts.side[0] = static_cast<std::int8_t>(side);
  return find_ghost(vertex, cuts);
}

void DeformableBody::check_cuts(std::span<const TetCut> cuts) const {
  std::vector<int> tets;
  tets.reserve(cuts.size());
  const auto has_plane = [](const TetCut& cut) {
    return std::count_if(cut.edge_ratio.begin(), cut.edge_ratio.end(), [](double r) { return r >= 0.0; }) >= 3;
  };
  for (size_t c = 0; c < cuts.size(); ++c) {
    const TetCut& cut = cuts[c];
    const std::string where = "enrich: cut " + std::to_string(c) + " (tet " + std::to_string(cut.tet) + "): ";
    if (cut.tet < 0 || cut.tet >= m_mesh.tet_count()) {
      throw ParameterError(where + "tet outside [0, " + std::to_string(m_mesh.tet_count()) + ")");
    }
    if (const int k = cut_tet_index(cut.tet); k >= 0) {
      const std::vector<TetCut>& earlier = m_cut_geometry[static_cast<size_t>(k)].cuts;
      if (std::any_of(earlier.begin(), earlier.end(), [&](const TetCut& e) { return e.cut_id == cut.cut_id; })) {
        throw ParameterError(where + "the tet is cut already by cut " + std::to_string(cut.cut_id));
      }
      if (earlier.size() >= static_cast<size_t>(MAX_PIECE_CUTS)) {
        throw ParameterError(where + "the tet carries " + std::to_string(MAX_PIECE_CUTS) + " cuts already");
      }
      if (!has_plane(cut) || !std::all_of(earlier.begin(), earlier.end(), has_plane)) {
        throw ParameterError(where + "cutting a cut tet needs the edge crossings of each cut");
      }
    }
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
    if (!(cut.min_volume_fraction > 0.0) || !(cut.min_volume_fraction < 0.5)) {
      throw ParameterError(where + "smallest piece fraction " + std::to_string(cut.min_volume_fraction) +
                           " is not in (0, 0.5)");
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
  const Eigen::VectorXd mass_before_kg = m_mass_kg;
  const EnrichmentResult result = enrich_pieces(cuts, {}, &state.displacement_m);
  grow_state(state);
  for (const int row : m_orphaned_rows) state.velocity_m_per_s.segment<3>(3 * row).setZero();
  // An existing unknown that gained mass keeps its momentum (an inelastic join of the new piece).
  for (Eigen::Index r = 0; r < mass_before_kg.size(); ++r) {
    if (m_mass_kg(r) > mass_before_kg(r)) state.velocity_m_per_s(r) *= mass_before_kg(r) / m_mass_kg(r);
  }
  return result;
}

EnrichmentResult DeformableBody::enrich(std::span<const TetCut> cuts,
                                        std::span<const std::vector<TetPositions>> offsets_m) {
  return enrich_pieces(cuts, offsets_m, nullptr);
}

void DeformableBody::add_ghost_loads(int k, double sign) {
  const int u_rows = m_dofs.free_vertex_count();
  const double tet_mass_kg = density_kg_per_m3(m_xfem.rest(k)) * m_xfem.rest(k).volume_m3;
  const double alpha_per_s = mass_damping_per_s(m_xfem.rest(k));
  for (size_t p = 0; p < m_xfem.piece_count(k); ++p) {
    const CutPiece& piece = m_xfem.piece(k, static_cast<int>(p));
    const double quarter_mass_kg = 0.25 * piece.weight * tet_mass_kg;
    for (size_t j = 0; j < 4; ++j) {
      const int row = piece.ghost_row[j];
      if (row < 0) continue;
      m_mass_kg.segment<3>(3 * row).array() += sign * quarter_mass_kg;
      m_mass_damping_kg_per_s.segment<3>(3 * row).array() += sign * alpha_per_s * quarter_mass_kg;
      m_external_force_n.segment<3>(3 * row) +=
          sign * piece.ghost_sign[j] * quarter_mass_kg * m_settings.gravity_m_per_s2;
      m_ghost_users[static_cast<size_t>(row - u_rows)] += sign > 0.0 ? 1 : -1;
    }
  }
}

namespace {

// The cuts of `geometry` that separate piece q from its local vertex j, as (cut id, H of the
// vertex) sorted by cut id; none when j lies in the piece.
SeparatingCuts separating_cuts(const CutTetGeometry& geometry, size_t q, size_t j) {
  SeparatingCuts separated;
  const PieceSides& sides = geometry.pieces[q].sides;
  for (size_t k = 0; k < geometry.cuts.size(); ++k) {
    const int vertex_side = geometry.cuts[k].side[j];
    if ((vertex_side > 0) == ((sides.above & (1u << k)) != 0)) continue;
    const auto n = static_cast<size_t>(separated.count++);
    separated.cut_id[n] = geometry.cuts[k].cut_id;
    separated.side[n] = static_cast<std::int8_t>(vertex_side);
  }
  for (int a = 1; a < separated.count; ++a) {  // insertion sort of at most MAX_PIECE_CUTS pairs
    for (int b = a; b > 0 && separated.cut_id[static_cast<size_t>(b)] < separated.cut_id[static_cast<size_t>(b - 1)];
         --b) {
      std::swap(separated.cut_id[static_cast<size_t>(b)], separated.cut_id[static_cast<size_t>(b - 1)]);
      std::swap(separated.side[static_cast<size_t>(b)], separated.side[static_cast<size_t>(b - 1)]);
    }
  }
  return separated;
}

// The plane of a cut for telling which face material a piece has: a cut given without its crossings
// (by hand, as in tests; a tet cut once needs none) crosses its edges at their middles.
CutPlane face_cut_plane(const std::array<Eigen::Vector3d, 4>& corners, TetCut cut) {
  for (size_t e = 0; e < 6; ++e) {
    const bool crossed =
        cut.side[static_cast<size_t>(TET_EDGES[e][0])] != cut.side[static_cast<size_t>(TET_EDGES[e][1])];
    if (crossed && cut.edge_ratio[e] < 0.0) cut.edge_ratio[e] = 0.5;
  }
  return cut_plane(corners, cut);
}

// Twice the area of the part of the triangle `face` (rest positions) that lies in piece q of a tet
// and in piece r of another: the triangle clipped by the planes (CutTetGeometry::planes) that bound
// either piece, each on its piece's side. No allocation: a triangle clipped by up to 2
// MAX_PIECE_CUTS planes has at most 3 + 2 MAX_PIECE_CUTS corners.
double shared_face_area(const std::array<Eigen::Vector3d, 3>& face, const CutTetGeometry& first, size_t q,
                        const CutTetGeometry& second, size_t r) {
  constexpr size_t CAPACITY = 3 + 2 * MAX_PIECE_CUTS + 1;
  std::array<Eigen::Vector3d, CAPACITY> polygon{face[0], face[1], face[2]};
  std::array<Eigen::Vector3d, CAPACITY> kept;
  size_t corners = 3;
  const auto clip = [&](const CutPlane& plane, bool above) {
    size_t count = 0;
    const double sign = above ? 1.0 : -1.0;
    for (size_t i = 0; i < corners; ++i) {
      const Eigen::Vector3d& a = polygon[i];
      const Eigen::Vector3d& b = polygon[(i + 1) % corners];
      const double da = sign * plane.signed_distance(a);
      const double db = sign * plane.signed_distance(b);
      if (da >= 0.0 && count < CAPACITY) kept[count++] = a;
      if (((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) && count < CAPACITY)
        kept[count++] = a + (b - a) * (da / (da - db));
    }
    std::copy(kept.begin(), kept.begin() + static_cast<std::ptrdiff_t>(count), polygon.begin());
    corners = count;
  };
  for (const auto& [geometry, piece] : {std::pair{&first, q}, std::pair{&second, r}}) {
    const PieceSides& sides = geometry->pieces[piece].sides;
    for (size_t k = 0; k < geometry->cuts.size() && corners >= 3; ++k) {
      if ((sides.bounded & (1u << k)) == 0) continue;
      clip(geometry->planes[k], (sides.above & (1u << k)) != 0);
    }
  }
  if (corners < 3) return 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < corners; ++i) normal += polygon[i].cross(polygon[(i + 1) % corners]);
  return normal.norm();
}

}  // namespace

// Enriched lumped mass and gravity for any number of pieces: each piece p lumped as a full tet of
// mass w_p m puts w_p m / 4 on each of its ghosts (as M^aa above), and its gravity on the ghost
// row is sign w_p m / 4 g (the ghost sits at x_j + sign a).
//
// Which ghost a piece uses (the virtual-node algorithm's node copies, Molino et al. 2004): around a
// vertex v, the pieces of the tets that hold v with the same separating cuts (separating_cuts) that
// touch across a shared face form one copy of v; each such group (connected component) is one ghost.
// Keying by the separating cuts alone joins pieces on either side of a stroke that ends at another
// (a flap's corner): there the same cuts separate two pieces from v that no material joins.
EnrichmentResult DeformableBody::enrich_pieces(std::span<const TetCut> cuts,
                                               std::span<const std::vector<TetPositions>> offsets_m,
                                               const Eigen::VectorXd* displacement_m) {
  check_cuts(cuts);
  // A cut tet to be made: for a cut of the batch, or to give an existing one other ghosts.
  struct Plan {
    int tet = -1;
    int old = -1;  // the live cut tet it replaces, or -1
    bool from_cut = true;
    CutTetGeometry geometry;
    std::vector<std::array<int, 4>> rows;  // per piece and local vertex: ghost row, -1 real, -2 - n the n-th new row
  };
  std::vector<Plan> plans;
  std::vector<int> plan_of_tet(static_cast<size_t>(m_mesh.tet_count()), -1);
  // Every cut's geometry first: nothing changes before all are known to be valid.
  for (size_t c = 0; c < cuts.size(); ++c) {
    Plan plan;
    plan.tet = cuts[c].tet;
    plan.old = cut_tet_index(cuts[c].tet);
    if (plan.old >= 0) plan.geometry.cuts = m_cut_geometry[static_cast<size_t>(plan.old)].cuts;
    plan.geometry.cuts.push_back(cuts[c]);
    const std::span<const TetPiece> previous =
        plan.old >= 0 ? std::span<const TetPiece>(m_cut_geometry[static_cast<size_t>(plan.old)].pieces)
                      : std::span<const TetPiece>();
    try {
      plan.geometry.pieces = split_pieces(m_mesh.rest_corners(plan.tet), plan.geometry.cuts, previous);
    } catch (const std::invalid_argument& error) {
      throw ParameterError("enrich: cut " + std::to_string(c) + ": " + error.what());
    }
    if (plan.geometry.pieces.size() < 2) throw ParameterError("enrich: cut " + std::to_string(c) + " leaves one piece");
    if (plan.old >= 0) plan.geometry.planes = m_cut_geometry[static_cast<size_t>(plan.old)].planes;
    plan.geometry.planes.push_back(face_cut_plane(m_mesh.rest_corners(plan.tet), cuts[c]));
    plan.rows.assign(plan.geometry.pieces.size(), {-1, -1, -1, -1});
    plan_of_tet[static_cast<size_t>(plan.tet)] = static_cast<int>(plans.size());
    plans.push_back(std::move(plan));
  }

  // The ghosts, vertex by vertex around the batch's tets.
  std::vector<SeparatingCuts> new_rows;  // keys of the rows to create
  std::vector<int> new_row_vertex;
  std::vector<int> vertices;
  for (const TetCut& cut : cuts) {
    for (const int v : m_mesh.tets[static_cast<size_t>(cut.tet)]) vertices.push_back(v);
  }
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  struct Node {
    int tet;
    size_t piece;
    size_t local;  // v's local index in the tet
    SeparatingCuts key;
    int candidate;  // the row it uses now (or its parent used), -1 none
  };
  std::vector<Node> nodes;
  std::vector<int> parent_of;  // union-find over nodes
  const auto find = [&](int i) {
    while (parent_of[static_cast<size_t>(i)] != i)
      i = parent_of[static_cast<size_t>(i)] = parent_of[static_cast<size_t>(parent_of[static_cast<size_t>(i)])];
    return i;
  };
  for (const int v : vertices) {
    nodes.clear();
    const auto star_begin = static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v)]);
    const auto star = std::span(m_adjacency.vertex_tets)
                          .subspan(star_begin, static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v) + 1]) -
                                                   star_begin);
    for (const int t : star) {
      const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
      const auto local = static_cast<size_t>(std::find(tet.begin(), tet.end(), v) - tet.begin());
      const int p = plan_of_tet[static_cast<size_t>(t)];
      const int k = cut_tet_index(t);
      if (p < 0 && k < 0) continue;  // uncut: v is real there
      const CutTetGeometry& geometry =
          p >= 0 ? plans[static_cast<size_t>(p)].geometry : m_cut_geometry[static_cast<size_t>(k)];
      for (size_t q = 0; q < geometry.pieces.size(); ++q) {
        const SeparatingCuts key = separating_cuts(geometry, q, local);
        if (key.count == 0) continue;
        int candidate = -1;
        if (p < 0) {
          candidate = m_xfem.piece(k, static_cast<int>(q)).ghost_row[local];
        } else if (const Plan& plan = plans[static_cast<size_t>(p)]; plan.from_cut && plan.old >= 0) {
          candidate = m_xfem.piece(plan.old, geometry.pieces[q].parent).ghost_row[local];
        } else if (!plan.from_cut) {
          candidate = plan.rows[q][local];
        }
        if (candidate >= 0 &&
            !(m_enriched_dofs[static_cast<size_t>(candidate - m_dofs.free_vertex_count())].separated_by == key)) {
          candidate = -1;  // a ghost behind other cuts
        }
        nodes.push_back(Node{t, q, local, key, candidate});
      }
    }
    // Components, key by key: pieces of the key and the uncut tets of the star (whose material is
    // whole), joined where two of them share a face with material of both on it.
    const auto geometry_of = [&](int t) -> const CutTetGeometry& {
      const int p = plan_of_tet[static_cast<size_t>(t)];
      return p >= 0 ? plans[static_cast<size_t>(p)].geometry : m_cut_geometry[static_cast<size_t>(cut_tet_index(t))];
    };
    const auto is_uncut = [&](int t) { return plan_of_tet[static_cast<size_t>(t)] < 0 && cut_tet_index(t) < 0; };
    // The faces the star's tets share (star indices and the face's rest corners).
    struct StarFace {
      size_t a, b;
      std::array<Eigen::Vector3d, 3> corners;
      double area_threshold;
    };
    std::vector<StarFace> faces;
    for (size_t a = 0; a < star.size(); ++a) {
      const int t = star[a];
      for (size_t k = 0; k < 4; ++k) {
        const int neighbour = m_adjacency.face_neighbor[static_cast<size_t>(t)][k];
        if (neighbour < t) continue;  // none, or the pair is seen from the other side
        const auto b = static_cast<size_t>(std::find(star.begin(), star.end(), neighbour) - star.begin());
        if (b == star.size()) continue;
        const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
        std::array<Eigen::Vector3d, 3> corners;
        for (size_t c = 0; c < 3; ++c)
          corners[c] = m_mesh.rest_positions_m[static_cast<size_t>(tet[static_cast<size_t>(TET_FACES[k][c])])];
        faces.push_back(
            StarFace{a, b, corners, 1e-9 * (corners[1] - corners[0]).cross(corners[2] - corners[0]).norm()});
      }
    }
    static const CutTetGeometry WHOLE{{}, {TetPiece{}}, {}};  // an uncut tet as a piece bounded by nothing
    std::vector<bool> done(nodes.size(), false);
    std::vector<std::vector<int>> elements(star.size());  // per star tet: its elements of this key
    for (size_t first = 0; first < nodes.size(); ++first) {
      if (done[first]) continue;
      std::vector<size_t> members;  // the nodes of this key; elements n, n + 1, ... are the uncut tets
      for (size_t i = first; i < nodes.size(); ++i) {
        if (nodes[i].key == nodes[first].key) members.push_back(i);
      }
      for (const size_t i : members) done[i] = true;
      const size_t n = members.size();
      for (auto& list : elements) list.clear();
      size_t count = n;
      for (size_t s = 0; s < star.size(); ++s) {
        if (is_uncut(star[s])) elements[s].push_back(static_cast<int>(count++));
      }
      for (size_t m = 0; m < n; ++m) {
        const auto s = static_cast<size_t>(std::find(star.begin(), star.end(), nodes[members[m]].tet) - star.begin());
        elements[s].push_back(static_cast<int>(m));
      }
      parent_of.resize(count);
      for (size_t i = 0; i < count; ++i) parent_of[i] = static_cast<int>(i);
      for (const StarFace& face : faces) {
        for (const int i : elements[face.a]) {
          for (const int j : elements[face.b]) {
            if (find(i) == find(j)) continue;
            const bool i_piece = static_cast<size_t>(i) < n;
            const bool j_piece = static_cast<size_t>(j) < n;
            const double area = !i_piece && !j_piece
                                    ? 1.0
                                    : shared_face_area(face.corners, i_piece ? geometry_of(star[face.a]) : WHOLE,
                                                       i_piece ? nodes[members[static_cast<size_t>(i)]].piece : 0,
                                                       j_piece ? geometry_of(star[face.b]) : WHOLE,
                                                       j_piece ? nodes[members[static_cast<size_t>(j)]].piece : 0);
            if (area > face.area_threshold) parent_of[static_cast<size_t>(find(j))] = find(i);
          }
        }
      }
      // Each component keeps the row most of its nodes use (one component per row), or gets a new one.
      std::vector<int> claimed;
      std::vector<int> roots;
      for (size_t m = 0; m < n; ++m) {
        const int root = find(static_cast<int>(m));
        if (std::find(roots.begin(), roots.end(), root) == roots.end()) roots.push_back(root);
      }
      for (const int root : roots) {
        std::map<int, int> votes;
        for (size_t m = 0; m < n; ++m) {
          if (find(static_cast<int>(m)) == root && nodes[members[m]].candidate >= 0)
            ++votes[nodes[members[m]].candidate];
        }
        int row = -1;
        int best = 0;
        for (const auto& [candidate, voters] : votes) {
          if (voters > best && std::find(claimed.begin(), claimed.end(), candidate) == claimed.end()) {
            row = candidate;
            best = voters;
          }
        }
        if (row < 0) {
          row = -2 - static_cast<int>(new_rows.size());
          new_rows.push_back(nodes[first].key);
          new_row_vertex.push_back(v);
        }
        claimed.push_back(row);
        for (size_t m = 0; m < n; ++m) {
          if (find(static_cast<int>(m)) != root) continue;
          const Node& node = nodes[members[m]];
          int p = plan_of_tet[static_cast<size_t>(node.tet)];
          if (p < 0) {
            const int k = cut_tet_index(node.tet);
            if (m_xfem.piece(k, static_cast<int>(node.piece)).ghost_row[node.local] == row) continue;
            // An existing cut tet whose piece moves to another ghost: made again with its ghosts.
            Plan plan;
            plan.tet = node.tet;
            plan.old = k;
            plan.from_cut = false;
            plan.geometry = m_cut_geometry[static_cast<size_t>(k)];
            for (int q = 0; q < static_cast<int>(m_xfem.piece_count(k)); ++q)
              plan.rows.push_back(m_xfem.piece(k, q).ghost_row);
            p = static_cast<int>(plans.size());
            plan_of_tet[static_cast<size_t>(node.tet)] = p;
            plans.push_back(std::move(plan));
          }
          plans[static_cast<size_t>(p)].rows[node.piece][node.local] = row;
        }
      }
    }
  }
  if (!offsets_m.empty()) {
    if (offsets_m.size() < plans.size()) {
      throw ParameterError("enrich: " + std::to_string(offsets_m.size()) + " offset lists for " +
                           std::to_string(plans.size()) + " cut tets");
    }
    for (size_t c = 0; c < plans.size(); ++c) {
      if (offsets_m[c].size() != plans[c].geometry.pieces.size()) {
        throw ParameterError("enrich: cut tet " + std::to_string(c) + " has " + std::to_string(offsets_m[c].size()) +
                             " offset sets for " + std::to_string(plans[c].geometry.pieces.size()) + " pieces");
      }
      for (const TetPositions& offsets : offsets_m[c]) {
        for (const Eigen::Vector3d& offset : offsets) {
          if (!offset.allFinite()) throw ParameterError("enrich: an enrichment offset is not finite");
        }
      }
    }
  }

  EnrichmentResult result;
  const std::uint64_t layout_before = m_tangent.layout_revision();
  const int u_rows = m_dofs.free_vertex_count();
  const int old_dofs = enriched_dof_count();
  const int first_new_cut_tet = m_xfem.cut_tet_count();
  std::vector<std::pair<int, int>> new_blocks;  // (row, column) the new cut tets couple
  m_orphaned_rows.clear();
  // The current a of an unknown (new ones, and every one without a running state, are zero).
  const auto current_a = [&](int row) -> Eigen::Vector3d {
    if (displacement_m == nullptr || 3 * row >= displacement_m->size()) return Eigen::Vector3d::Zero();
    return displacement_m->segment<3>(3 * row);
  };

  // 1. The new ghosts' rows; a new row's sign is -H of the vertex for its first separating cut (a
  // single cut: Psi = (H_p - H_j) / 2 = -H_j).
  for (size_t n = 0; n < new_rows.size(); ++n) {
    const int vertex = new_row_vertex[n];
    const int k = enriched_dof_count();
    const int row = m_tangent.append_block_row(m_enriched_row_capacity[static_cast<size_t>(vertex)]);
    if (row != u_rows + k) throw std::logic_error("enrich: the tangent's rows and the unknowns disagree");
    m_enriched_dofs.push_back(EnrichedDof{vertex, new_rows[n].cut_id[0], new_rows[n].side[0], row, new_rows[n]});
    m_next_enriched_dof.push_back(m_first_enriched_dof[static_cast<size_t>(vertex)]);
    m_first_enriched_dof[static_cast<size_t>(vertex)] = k;
  }
  const auto row_of = [&](int planned) { return planned >= -1 ? planned : u_rows + old_dofs + (-2 - planned); };
  const auto sign_of = [&](int row) {
    return -static_cast<double>(m_enriched_dofs[static_cast<size_t>(row - u_rows)].separated_by.side[0]);
  };
  m_ghost_users.resize(static_cast<size_t>(enriched_dof_count()), 0);
  m_mass_kg.conservativeResize(dof_count());
  m_mass_damping_kg_per_s.conservativeResize(dof_count());
  m_external_force_n.conservativeResize(dof_count());
  m_mass_kg.tail(3 * (enriched_dof_count() - old_dofs)).setZero();
  m_mass_damping_kg_per_s.tail(3 * (enriched_dof_count() - old_dofs)).setZero();
  m_external_force_n.tail(3 * (enriched_dof_count() - old_dofs)).setZero();

  for (size_t c = 0; c < plans.size(); ++c) {
    Plan& plan = plans[c];
    const int old = plan.old;
    CutTetGeometry& geometry = plan.geometry;
    const Tet& tet = m_mesh.tets[static_cast<size_t>(plan.tet)];

    // 2. The pieces: rows and signs, and where each starts: where its parent had the vertex.
    std::vector<CutPiece> pieces(geometry.pieces.size());
    std::vector<Eigen::Matrix3d> rotations(geometry.pieces.size(), m_elasticity.rotation(plan.tet));
    for (size_t q = 0; q < pieces.size(); ++q) {
      CutPiece& piece = pieces[q];
      piece.weight = geometry.pieces[q].volume_fraction;
      const int parent_index = plan.from_cut ? geometry.pieces[q].parent : static_cast<int>(q);
      const CutPiece* parent = old >= 0 ? &m_xfem.piece(old, parent_index) : nullptr;
      if (old >= 0) rotations[q] = m_xfem.rotation(old, parent_index);
      for (size_t j = 0; j < 4; ++j) {
        const int row = row_of(plan.rows[q][j]);
        if (row < 0) continue;
        const double sign = sign_of(row);
        piece.ghost_row[j] = row;
        piece.ghost_sign[j] = sign;
        if (!offsets_m.empty()) {
          piece.offset_m[j] = offsets_m[c][q][j];
        } else {
          Eigen::Vector3d from_real_m = Eigen::Vector3d::Zero();
          if (parent != nullptr && parent->ghost_row[j] >= 0) {
            from_real_m = parent->ghost_sign[j] * (current_a(parent->ghost_row[j]) - parent->offset_m[j]);
          }
          piece.offset_m[j] = current_a(row) - sign * from_real_m;
        }
      }
    }

    // 3. Mass and external force: the retired cut tet's share leaves its ghosts, the new one's arrives.
    if (old >= 0) {
      add_ghost_loads(old, -1.0);
      m_xfem.retire(old);
    } else {
      m_elasticity.exclude(plan.tet);
      ++m_tets_cut;
    }
    CutTet cut_tet;
    cut_tet.cut = geometry.cuts.front();
    cut_tet.vertices = tet;
    if (pieces.size() == 2 && geometry.cuts.size() == 1) {
      cut_tet.weight_above = pieces[0].weight;
      cut_tet.weight_below = pieces[1].weight;
      for (size_t j = 0; j < 4; ++j) {
        const CutPiece& ghost_piece = pieces[geometry.cuts.front().side[j] > 0 ? 1 : 0];  // the piece across the cut
        cut_tet.enriched_row[j] = ghost_piece.ghost_row[j];
        cut_tet.enrichment_offset_m[j] = ghost_piece.offset_m[j];
      }
    } else {
      cut_tet.enriched_row = {-1, -1, -1, -1};
    }
    const int k = m_xfem.cut_tet_count();
    m_cut_index[static_cast<size_t>(plan.tet)] = k;
    m_xfem.add(cut_tet, pieces, m_elasticity.rest(plan.tet), rotations);
    m_cut_geometry.push_back(std::move(geometry));
    add_ghost_loads(k, 1.0);
    // A ghost no piece uses any more (its pieces moved to other ghosts): it keeps a mass so the
    // system stays regular, and loses its load; nothing moves it.
    if (old >= 0) {
      for (const int row : m_xfem.ghost_rows(old)) {
        const auto dof = static_cast<size_t>(row - u_rows);
        if (m_ghost_users[dof] != 0 ||
            std::find(m_orphaned_rows.begin(), m_orphaned_rows.end(), row) != m_orphaned_rows.end())
          continue;
        const auto vertex = static_cast<size_t>(m_enriched_dofs[dof].vertex);
        m_mass_kg.segment<3>(3 * row).setConstant(m_vertex_mass_kg[vertex]);
        m_mass_damping_kg_per_s.segment<3>(3 * row).setConstant(m_vertex_mass_damping_kg_per_s[vertex]);
        m_external_force_n.segment<3>(3 * row).setZero();
        m_orphaned_rows.push_back(row);
      }
    }

    // 4. The blocks its pieces couple beyond u-u (which exist already): listed, inserted below.
    const int dofs = m_xfem.dof_count(k);
    for (int r = 0; r < dofs; ++r) {
      for (int col = 0; col < dofs; ++col) {
        if (r < 4 && col < 4) continue;
        if (!m_xfem.couples(k, r, col)) continue;  // identically zero
        const int row = cut_tet_dof_row(k, r);
        const int column = cut_tet_dof_row(k, col);
        if (row < 0 || column < 0) continue;  // a fixed vertex's u
        new_blocks.emplace_back(row, column);
      }
    }
  }
  // The batch's new blocks: room for all of them at once (rows start compact, MatrixReserve), then in.
  // The rows around the cut tets also get a cut's room (their ghost room, as an enriched row's), so
  // that the next strokes of a blade moving on find it: one re-layout where a cut starts, not one
  // per step.
  std::sort(new_blocks.begin(), new_blocks.end());
  new_blocks.erase(std::unique(new_blocks.begin(), new_blocks.end()), new_blocks.end());
  std::map<int, int> extra_of_row;
  for (const auto& [row, column] : new_blocks) {
    if (m_tangent.find_slot(row, column) < 0) ++extra_of_row[row];
  }
  for (int k = first_new_cut_tet; k < m_xfem.cut_tet_count(); ++k) {
    for (const int v : m_xfem.cut_tets()[static_cast<size_t>(k)].vertices) {
      const auto first = static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v)]);
      const auto end = static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v) + 1]);
      for (size_t e = first; e < end; ++e) {
        for (const int w : m_mesh.tets[static_cast<size_t>(m_adjacency.vertex_tets[e])]) {
          const int row = vertex_block_row(w);
          if (row < 0) continue;
          const int room = m_enriched_row_capacity[static_cast<size_t>(w)] - m_tangent.row_size(row);
          int& extra = extra_of_row[row];
          extra = std::max(extra, room);
        }
      }
    }
  }
  m_tangent.reserve_room(std::vector<std::pair<int, int>>(extra_of_row.begin(), extra_of_row.end()));
  for (const auto& [row, column] : new_blocks) m_tangent.insert_block(row, column);
  // An orphan that a later cut tet of the batch took up again is no orphan.
  std::erase_if(m_orphaned_rows, [&](int row) { return m_ghost_users[static_cast<size_t>(row - u_rows)] != 0; });
  result.new_cut_tets = static_cast<int>(plans.size());
  result.new_enriched_dofs = enriched_dof_count() - old_dofs;

  // 5. Slots: of the new cut tets only, unless the storage moved (a row outgrew its room).
  result.matrix_relayout = m_tangent.layout_revision() != layout_before;
  if (result.matrix_relayout) {
    refresh_all_slots(m_tangent.layout_revision() == layout_before + 1);
  } else {
    for (int k = first_new_cut_tet; k < m_xfem.cut_tet_count(); ++k) refresh_cut_tet_slots(k);
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

void DeformableBody::refresh_all_slots(bool one_relayout) {
  if (one_relayout) {
    // The uncut tets' blocks moved by the re-layout's map: no search (52k tets x 16 blocks).
    const std::vector<int>& moved = m_tangent.relayout_slot_map();
    for (TetSlots& tet_slots : m_slots) {
      for (int& slot : tet_slots) {
        if (slot >= 0) slot = moved[static_cast<size_t>(slot)];
      }
    }
  } else {
    m_slots = make_tet_slots(m_mesh, m_dofs, m_tangent);
  }
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

TetPositions DeformableBody::piece_positions(const Eigen::VectorXd& displacement_m, int cut_tet_index,
                                             int piece) const {
  const CutTet& cut_tet = m_xfem.cut_tets().at(static_cast<size_t>(cut_tet_index));
  TetPositions real_m;
  for (size_t j = 0; j < 4; ++j) {
    const int vertex = cut_tet.vertices[j];
    const int row = vertex_block_row(vertex);
    real_m[j] = m_mesh.rest_positions_m[static_cast<size_t>(vertex)];
    if (row >= 0) real_m[j] += displacement_m.segment<3>(3 * row);
  }
  return tissue::piece_positions(m_xfem.piece(cut_tet_index, piece), real_m, displacement_m);
}

double DeformableBody::piece_mass_kg(int cut_tet_index, int piece) const {
  return density_kg_per_m3(m_xfem.rest(cut_tet_index)) * m_xfem.piece(cut_tet_index, piece).weight *
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
