// DeformableBody: scatter the unknowns to vertex positions, evaluate the FEM (uncut tets, cut
// tets, point spring), gather forces back. Growing the system in place when tets are cut (enrich)
// is in deformable_body_enrich.cpp and deformable_body_ghosts.cpp.
#include "core/fem/deformable_body.hpp"

#include "core/fem/rotation.hpp"
#include "core/mesh/topology.hpp"

#include <algorithm>
#include <array>
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

// The vertices without unknowns: the fixed ones and those no tet uses, which have no mass and no
// stiffness (a row of zeros would make the system singular; readers warn of them, mesh_io.hpp).
std::vector<int> held_vertices(const std::vector<int>& fixed_vertices, const TetMesh& mesh) {
  std::vector<char> held(static_cast<size_t>(mesh.vertex_count()), 1);
  for (const Tet& tet : mesh.tets) {
    for (const int v : tet) held[static_cast<size_t>(v)] = 0;
  }
  for (const int v : fixed_vertices) held[static_cast<size_t>(v)] = 1;
  std::vector<int> vertices;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (held[static_cast<size_t>(v)] != 0) vertices.push_back(v);
  }
  return vertices;
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

// Room cuts need, so that cutting does not overflow a row (docs/DESIGN.md, "Linear solvers and
// system": room made where a cut goes). A u row holds its free neighbours and gains a u-a block for
// every ghost of a neighbour, fixed ones included: one per neighbour for a single cut, up to three
// where two cuts cross (the ghosts behind the first, the second and both): free +
// GHOSTS_PER_NEIGHBOUR all. An enriched row holds a-u blocks with the free neighbours and a-a blocks
// with their ghosts, as many.
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
      m_dofs(make_dof_map(m_mesh.vertex_count(), held_vertices(m_settings.fixed_vertices, m_mesh), m_vertex_order)),
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
  static_assert(XfemElasticity::LIST_PARTS == CorotationalElasticity::ASSEMBLY_PARTS);
  m_xfem.set_assembly_lists(m_elasticity.assembly_list_of_tets(),
                            static_cast<int>(m_elasticity.assembly_phases().size()));
  for (int t = 0; t < m_mesh.tet_count(); ++t) {
    m_largest_shape_gradient_per_m = std::max(m_largest_shape_gradient_per_m,
                                              m_elasticity.rest(t).shape_gradients_per_m.colwise().norm().maxCoeff());
  }
}

bool DeformableBody::held_tet(int t) const {
  const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
  return std::all_of(tet.begin(), tet.end(), [&](int v) { return vertex_block_row(v) < 0; });
}

const SeparatingCuts& DeformableBody::copy_separated_by(int ghost_row) const {
  static const SeparatingCuts NONE;
  if (is_held_copy(ghost_row)) return m_held_copies.at(static_cast<size_t>(held_copy_index(ghost_row))).separated_by;
  if (ghost_row < 0) return NONE;
  // Ghost row r is enriched unknown r - free_vertex_count() (append_ghost_rows checks it).
  return m_enriched_dofs.at(static_cast<size_t>(ghost_row - m_dofs.free_vertex_count())).separated_by;
}

const std::vector<Eigen::Matrix3d>* DeformableBody::block_frames() const {
  // A vertex's frame: the mean turn of its uncut tets, their unit quaternions summed (each signed
  // to agree with the sum so far: q and -q are one turn) and normalized, so it depends on the
  // rotations alone (no history). It turns a factor made earlier (turned_factor.hpp), a
  // preconditioner: this mean agrees to second order with the rotation nearest the rotations' sum,
  // which cost a polar decomposition per vertex (4% of a corrected CHOLMOD step on the frog).
  const size_t vertices = static_cast<size_t>(m_mesh.vertex_count());
  m_vertex_turns.assign(vertices, Eigen::Vector4d::Zero());
  for (int t = 0; t < m_elasticity.tet_count(); ++t) {
    if (m_elasticity.is_excluded(t)) continue;
    const Eigen::Vector4d turn = m_elasticity.turn(t).coeffs();
    for (const int v : m_mesh.tets[static_cast<size_t>(t)]) {
      Eigen::Vector4d& sum = m_vertex_turns[static_cast<size_t>(v)];
      if (sum.dot(turn) < 0.0) {
        sum -= turn;
      } else {
        sum += turn;
      }
    }
  }
  m_vertex_frames.resize(vertices);
  for (size_t v = 0; v < vertices; ++v) {
    const double norm = m_vertex_turns[v].norm();
    m_vertex_frames[v] = norm > 0.0 ? Eigen::Quaterniond(Eigen::Vector4d(m_vertex_turns[v] / norm)).toRotationMatrix()
                                    : Eigen::Matrix3d::Identity();
  }
  m_block_frames.resize(static_cast<size_t>(m_tangent.block_rows()));
  for (int row = 0; row < m_dofs.free_vertex_count(); ++row) {
    m_block_frames[static_cast<size_t>(row)] =
        m_vertex_frames[static_cast<size_t>(m_dofs.row_vertex[static_cast<size_t>(row)])];
  }
  // An enriched unknown moves the part of a cut tet beyond its vertex; it takes the vertex's frame.
  for (const EnrichedDof& dof : m_enriched_dofs) {
    m_block_frames[static_cast<size_t>(dof.row)] = m_vertex_frames[static_cast<size_t>(dof.vertex)];
  }
  return &m_block_frames;
}

const std::vector<Eigen::Vector3d>* DeformableBody::block_positions(const Eigen::VectorXd& displacement_m) const {
  m_block_positions.resize(static_cast<size_t>(m_tangent.block_rows()));
  const auto moved = [&](int row, int vertex) {
    m_block_positions[static_cast<size_t>(row)] =
        m_mesh.rest_positions_m[static_cast<size_t>(vertex)] + displacement_m.segment<3>(3L * row);
  };
  for (int row = 0; row < m_dofs.free_vertex_count(); ++row) moved(row, m_dofs.row_vertex[static_cast<size_t>(row)]);
  for (const EnrichedDof& dof : m_enriched_dofs) moved(dof.row, dof.vertex);
  return &m_block_positions;
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

void DeformableBody::evaluate_pass(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n,
                                   bool update_tangent, bool with_potential, ExtractInto into) {
  check_unknowns(displacement_m);
  ++m_changes;
  m_ahead.pending = false;
  positions(displacement_m, m_positions_m);
  m_vertex_forces_n.setZero();
  if (update_tangent) m_tangent.set_zero(m_team);
  BlockSparseMatrix* tangent = update_tangent ? &m_tangent : nullptr;
  double uncut_energy_j = 0.0;
  double cut_energy_j = 0.0;
  m_elasticity.evaluate(m_positions_m, m_vertex_forces_n, tangent, &m_slots, m_team,
                        with_potential ? &uncut_energy_j : nullptr, into);
  internal_force_n.resize(dof_count());
  const int u_rows = m_dofs.free_vertex_count();
  internal_force_n.tail(3 * enriched_dof_count()).setZero();
  m_xfem.evaluate(m_positions_m, displacement_m, m_vertex_forces_n, internal_force_n, tangent,
                  with_potential ? &cut_energy_j : nullptr, into, m_team);

  for (ForceTerm* term : m_force_terms) {
    term->add_force(m_positions_m, m_vertex_forces_n);
    if (tangent != nullptr) term->add_tangent(*tangent);
  }
  // potential_energy_j's sum, from this pass's rotations.
  m_evaluated_potential_j = with_potential ? potential_with_elastic_j(uncut_energy_j + cut_energy_j, displacement_m)
                                           : std::numeric_limits<double>::quiet_NaN();

  for (int row = 0; row < u_rows; ++row) {
    internal_force_n.segment<3>(3 * row) =
        m_vertex_forces_n.segment<3>(3 * m_dofs.row_vertex[static_cast<size_t>(row)]);
  }
}

bool DeformableBody::evaluate_ahead(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n) {
  const bool cutting = m_element_revision != m_element_revision_at_ahead;
  m_element_revision_at_ahead = m_element_revision;
  if (cutting) return false;  // a stroke under way: the next step's cut would change the body again
  for (const ForceTerm* term : m_force_terms) {
    if (!term->idle()) return false;  // the tool moves between steps: it would not be taken
  }
  evaluate_pass(displacement_m, internal_force_n, /*update_tangent=*/true, /*with_potential=*/true, ExtractInto::ahead);
  m_ahead.pending = true;
  m_ahead.revision = evaluation_revision();
  m_ahead.displacement_m = displacement_m;
  return true;
}

bool DeformableBody::take_evaluation_ahead(const Eigen::VectorXd& displacement_m) {
  const bool taken = m_ahead.pending && m_ahead.revision == evaluation_revision() &&
                     m_ahead.displacement_m.size() == displacement_m.size() &&
                     (m_ahead.displacement_m.array() == displacement_m.array()).all();
  m_ahead.pending = false;
  if (taken) {
    m_elasticity.take_ahead();
    m_xfem.take_ahead();
  }
  return taken;
}

double DeformableBody::elastic_energy_j(const Eigen::VectorXd& displacement_m) {
  check_unknowns(displacement_m);
  positions(displacement_m, m_positions_m);
  return m_elasticity.elastic_energy_j(m_positions_m, m_team) +
         m_xfem.elastic_energy_j(m_positions_m, displacement_m, m_team);
}

double DeformableBody::potential_energy_j(const Eigen::VectorXd& displacement_m) {
  const double energy_j = potential_with_elastic_j(elastic_energy_j(displacement_m), displacement_m);  // positions set
  m_kept_potential.energy_j = energy_j;
  m_kept_potential.revision = evaluation_revision();
  m_kept_potential.displacement_m = displacement_m;
  return energy_j;
}

double DeformableBody::kept_potential_energy_j(const Eigen::VectorXd& displacement_m) const {
  const KeptPotential& kept = m_kept_potential;
  const bool same = kept.revision == evaluation_revision() && kept.displacement_m.size() == displacement_m.size() &&
                    (kept.displacement_m.array() == displacement_m.array()).all();
  return same ? kept.energy_j : std::numeric_limits<double>::quiet_NaN();
}

double DeformableBody::potential_with_elastic_j(double elastic_energy_j, const Eigen::VectorXd& displacement_m) const {
  double energy = elastic_energy_j - m_external_force_n.dot(displacement_m);
  for (const ForceTerm* term : m_force_terms) energy += term->energy_j(m_positions_m);
  return energy;
}

double DeformableBody::kinetic_energy_j(const Eigen::VectorXd& velocity_m_per_s) const {
  return 0.5 * velocity_m_per_s.dot(m_mass_kg.cwiseProduct(velocity_m_per_s));
}

void DeformableBody::save_rotations(Rotations& rotations) const {
  rotations.tets = m_elasticity.rotations();
  rotations.tet_warm_starts = m_elasticity.warm_starts();
  rotations.tet_turns_before = m_elasticity.turns_before();
  rotations.pieces = m_xfem.piece_rotations();
  rotations.piece_warm_starts = m_xfem.piece_warm_starts();
  rotations.piece_turns_before = m_xfem.piece_turns_before();
}

void DeformableBody::check_rotations(const Rotations& rotations) const {
  const size_t tets = static_cast<size_t>(m_mesh.tet_count());
  const size_t pieces = m_xfem.piece_rotations().size();
  if (rotations.tets.size() != tets || rotations.tet_warm_starts.size() != tets ||
      rotations.tet_turns_before.size() != tets || rotations.pieces.size() != pieces ||
      rotations.piece_warm_starts.size() != pieces || rotations.piece_turns_before.size() != pieces) {
    throw std::invalid_argument("body: the saved rotations are of " + std::to_string(rotations.tets.size()) +
                                " tets and " + std::to_string(rotations.pieces.size()) + " cut-tet pieces, the body has " +
                                std::to_string(tets) + " and " + std::to_string(m_xfem.piece_rotations().size()));
  }
  const auto check_all = [](const auto& values, const auto& is_one, const char* what) {
    for (size_t k = 0; k < values.size(); ++k) {
      if (!is_one(values[k])) throw std::invalid_argument("body: saved " + std::string(what) + " " + std::to_string(k) + " is not one");
    }
  };
  check_all(rotations.tets, is_rotation, "tet rotation");
  check_all(rotations.tet_warm_starts, is_unit_quaternion, "tet warm start (a unit quaternion)");
  check_all(rotations.pieces, is_rotation, "piece rotation");
  check_all(rotations.piece_warm_starts, is_unit_quaternion, "piece warm start (a unit quaternion)");
  check_all(rotations.tet_turns_before, is_unit_quaternion, "tet turn before (a unit quaternion)");
  check_all(rotations.piece_turns_before, is_unit_quaternion, "piece turn before (a unit quaternion)");
}

void DeformableBody::restore_rotations(const Rotations& rotations) {
  check_rotations(rotations);
  changed();
  m_elasticity.restore_rotations(rotations.tets, rotations.tet_warm_starts, rotations.tet_turns_before);
  m_xfem.restore_rotations(rotations.pieces, rotations.piece_warm_starts, rotations.piece_turns_before);
}

void DeformableBody::reset_rotations() {
  changed();
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

int DeformableBody::cut_tet_dof_row(int cut_tet_index, int dof) const {
  if (dof < 4) {
    return vertex_block_row(m_xfem.cut_tets()[static_cast<size_t>(cut_tet_index)].vertices[static_cast<size_t>(dof)]);
  }
  return m_xfem.ghost_rows(cut_tet_index)[static_cast<size_t>(dof - 4)];
}

void DeformableBody::refresh_cut_tet_slots(int cut_tet_index, const std::vector<int>* moved) {
  const CutTet& cut_tet = m_xfem.cut_tets()[static_cast<size_t>(cut_tet_index)];
  const int dofs = m_xfem.dof_count(cut_tet_index);
  const auto row_of = [&](int dof) { return cut_tet_dof_row(cut_tet_index, dof); };
  const CutTetSlots slots = m_xfem.slots(cut_tet_index);
  if (m_xfem.retired(cut_tet_index)) {
    std::fill(slots.begin(), slots.end(), -1);
    return;
  }
  std::vector<std::uint8_t> coupled;
  m_xfem.coupled_dofs(cut_tet_index, coupled);
  for (int r = 0; r < dofs; ++r) {
    for (int col = 0; col < dofs; ++col) {
      int& slot = slots[static_cast<size_t>(dofs * r + col)];
      if (coupled[static_cast<size_t>(dofs * r + col)] == 0 || row_of(r) < 0 || row_of(col) < 0) {
        slot = -1;
        continue;
      }
      // Where the one re-layout since moved it (a pair's block stays while a piece uses it), else searched.
      slot = moved != nullptr && slot >= 0 ? (*moved)[static_cast<size_t>(slot)] : -1;
      if (slot < 0) slot = m_tangent.find_slot(row_of(r), row_of(col));
      if (slot < 0)
        throw std::logic_error("enrich: a block of cut tet " + std::to_string(cut_tet.cut.tet) + " is missing");
    }
  }
}

bool DeformableBody::drop_retired_blocks(PackRows pack) {
  const int u_rows = m_dofs.free_vertex_count();
  std::vector<std::uint8_t> keep(static_cast<size_t>(m_tangent.slot_capacity()), 0);
  // The blocks between two u rows stay (the uncut tets' and the force terms'): only XFEM blocks can
  // be left over.
  for (int row = 0; row < u_rows; ++row) {
    const int begin = m_tangent.row_begin(row);
    for (int slot = begin; slot < begin + m_tangent.row_size(row); ++slot) {
      if (m_tangent.slot_column(slot) < u_rows) keep[static_cast<size_t>(slot)] = 1;
    }
  }
  for (int k = 0; k < m_xfem.cut_tet_count(); ++k) {
    if (!m_xfem.retired(k)) m_xfem.mark_written_slots(k, keep);
  }
  m_retired_slots = 0;
  const bool packed = pack == PackRows::always || static_cast<double>(m_tangent.row_room()) >
                                                      ROW_ROOM_PER_BLOCK_TO_PACK * m_tangent.nonzero_blocks();
  using RowRoom = BlockSparseMatrix::RowRoom;
  if (!m_tangent.remove_blocks(keep, packed ? RowRoom::packed : RowRoom::kept)) return false;
  changed();
  refresh_all_slots(/*one_relayout=*/true);
  return true;
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
  for (int k = 0; k < m_xfem.cut_tet_count(); ++k) {
    refresh_cut_tet_slots(k, one_relayout ? &m_tangent.relayout_slot_map() : nullptr);
  }
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
  return tissue::piece_positions(m_xfem.piece(cut_tet_index, piece), real_m, cut_tet.rest_m, displacement_m);
}

std::array<int, 4> DeformableBody::piece_rows(int cut_tet_index, int piece) const {
  const CutPiece& of = m_xfem.piece(cut_tet_index, piece);
  const Tet& vertices = m_xfem.cut_tets()[static_cast<size_t>(cut_tet_index)].vertices;
  std::array<int, 4> rows{};
  for (size_t j = 0; j < 4; ++j) rows[j] = of.ghost_row[j] >= 0 ? of.ghost_row[j] : vertex_block_row(vertices[j]);
  return rows;
}

double DeformableBody::piece_mass_kg(int cut_tet_index, int piece) const {
  return density_kg_per_m3(m_xfem.rest(cut_tet_index)) * m_xfem.piece(cut_tet_index, piece).weight *
         m_xfem.rest(cut_tet_index).volume_m3;
}

std::uint64_t DeformableBody::evaluation_revision() const {
  std::uint64_t revision = m_changes;
  for (const ForceTerm* term : m_force_terms) revision += term->revision();  // each only grows
  return revision;
}

// --- Force terms ---

void DeformableBody::attach(ForceTerm& term) {
  changed();
  if (std::find(m_force_terms.begin(), m_force_terms.end(), &term) == m_force_terms.end()) {
    m_force_terms.push_back(&term);
  }
  term.locate(term_layout());
}

void DeformableBody::detach(ForceTerm& term) {
  changed();
  std::erase(m_force_terms, &term);
}

}  // namespace tissue
