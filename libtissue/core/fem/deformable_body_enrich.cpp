// DeformableBody's XFEM enrichment (deformable_body.hpp: enrich): the cut tets' pieces and the system
// grown in place; which ghost each piece uses is in deformable_body_ghosts.cpp.
//
// Lumped mass and gravity of the pieces (docs/DESIGN.md, "Equations and errata": eq. 4.16 is
// garbled). Each piece p of a cut tet is lumped as a full tet of mass w_p m: it puts w_p m / 4 and
// its weight w_p m / 4 g on each of the 4 rows it uses (a real vertex's u or a ghost's c), and the
// uncut tet's m / 4 leaves the real vertices' rows. The rows are the copies' own displacements, so
// this lumping is diagonal and exact for rigid motion: a piece cut free carries exactly its mass and
// its weight and falls at g (issue 40; the dissertation's shifted enrichment a = u - c couples u and
// a by an off-diagonal block M^ua that a diagonal lumping drops, which made a freed beam end fall at
// 8.5 m/s^2). A new ghost starts as a copy of the copy it splits from (its displacement and
// velocity), so a cut moves nothing and keeps the momentum; a piece that joins a ghost that has
// moved keeps its place by an offset and brings its momentum (an inelastic join).
#include "core/fem/deformable_body.hpp"

#include "core/fem/deformable_body_enrich.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tissue {

namespace {

// A cut within what the XFEM can carry (a saved state may hold any numbers: found by fuzzing, issue
// 44): its smallest piece fraction and both its parts at least the floor SMALLEST_MIN_VOLUME_FRACTION
// (a part of 5e-324 gave a ghost no mass and no stiffness; the cutter clamps to its own, larger,
// smallest fraction, exact cuts made in code go down to the floor), its crossings on their edges, its
// blade normal finite.
void check_fractions(const TetCut& cut, const std::string& where) {
  if (!(cut.min_volume_fraction >= SMALLEST_MIN_VOLUME_FRACTION) || !(cut.min_volume_fraction < 0.5)) {
    throw ParameterError(where + "smallest piece fraction " + std::to_string(cut.min_volume_fraction) +
                         " is not in [1e-12, 0.5)");
  }
  constexpr double FLOOR = SMALLEST_MIN_VOLUME_FRACTION * (1.0 - 1e-9);  // to rounding
  if (!(cut.volume_fraction_above >= FLOOR) || !(cut.volume_fraction_above <= 1.0 - FLOOR)) {
    throw ParameterError(where + "volume fraction " + std::to_string(cut.volume_fraction_above) +
                         " is not in [1e-12, 1 - 1e-12]");
  }
  for (const double r : cut.edge_ratio) {
    if (r != -1.0 && !(r >= 0.0 && r <= 1.0)) {
      throw ParameterError(where + "an edge crossing " + std::to_string(r) + " is neither -1 nor in [0, 1]");
    }
  }
  if (!cut.blade_normal.allFinite()) throw ParameterError(where + "the blade normal is not finite");
}

}  // namespace

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
      // One cut may cross a tet twice (a spiral tighter than the tet), never at the same place.
      if (std::any_of(earlier.begin(), earlier.end(), [&](const TetCut& e) {
            return e.cut_id == cut.cut_id && e.side == cut.side && e.edge_ratio == cut.edge_ratio;
          })) {
        throw ParameterError(where + "the tet is cut already by cut " + std::to_string(cut.cut_id) + " there");
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
    check_fractions(cut, where);
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
  const Eigen::VectorXd velocity_before_m_per_s = state.velocity_m_per_s;
  const EnrichmentResult result = enrich_pieces(cuts, {}, &state.displacement_m);
  grow_state(state);
  const int first_new_row = static_cast<int>(size / 3);
  for (size_t n = 0; n < m_new_row_start_m.size(); ++n) {
    state.displacement_m.segment<3>(3 * (first_new_row + static_cast<int>(n))) =
        m_new_row_start_m[n].value_or(Eigen::Vector3d::Zero());
  }
  // Momentum: a row keeps its own (of the mass that stayed) and gains what arrives with the pieces
  // that came from other copies.
  std::map<int, std::pair<double, Eigen::Vector3d>> arrived;  // row: mass, momentum
  for (const CopyArrival& arrival : m_arrivals) {
    auto& [mass_kg, momentum] = arrived.try_emplace(arrival.row, 0.0, Eigen::Vector3d::Zero()).first->second;
    mass_kg += arrival.mass_kg;
    if (arrival.from_row >= 0) momentum += arrival.mass_kg * velocity_before_m_per_s.segment<3>(3 * arrival.from_row);
  }
  for (const auto& [row, arrival] : arrived) {
    const double mass_kg = m_mass_kg(3 * row);
    const Eigen::Vector3d stayed = row < first_new_row
                                       ? Eigen::Vector3d(std::max(mass_kg - arrival.first, 0.0) *
                                                         velocity_before_m_per_s.segment<3>(3 * row))
                                       : Eigen::Vector3d::Zero();
    state.velocity_m_per_s.segment<3>(3 * row) = (stayed + arrival.second) / mass_kg;
  }
  for (const int row : m_orphaned_rows) state.velocity_m_per_s.segment<3>(3 * row).setZero();
  return result;
}

EnrichmentResult DeformableBody::enrich(std::span<const TetCut> cuts,
                                        std::span<const std::vector<TetPositions>> offsets_m) {
  return enrich_pieces(cuts, offsets_m, nullptr);
}

void DeformableBody::add_piece_loads(int k, double sign) {
  const int u_rows = m_dofs.free_vertex_count();
  const double mass_kg = tet_mass_kg(m_xfem.rest(k));
  const double alpha_per_s = mass_damping_per_s(m_xfem.rest(k));
  for (size_t p = 0; p < m_xfem.piece_count(k); ++p) {
    const CutPiece& piece = m_xfem.piece(k, static_cast<int>(p));
    const double quarter_mass_kg = 0.25 * piece.weight * mass_kg;
    const std::array<int, 4> rows = piece_rows(k, static_cast<int>(p));
    for (size_t j = 0; j < 4; ++j) {
      const int row = rows[j];
      if (row < 0) continue;  // a fixed vertex
      add_row_load(row, sign * quarter_mass_kg, alpha_per_s);
      if (piece.ghost_row[j] >= 0) m_ghost_users[static_cast<size_t>(row - u_rows)] += sign > 0.0 ? 1 : -1;
    }
  }
}

void DeformableBody::add_row_load(int row, double mass_kg, double alpha_per_s) {
  m_mass_kg.segment<3>(3 * row).array() += mass_kg;
  m_mass_damping_kg_per_s.segment<3>(3 * row).array() += alpha_per_s * mass_kg;
  m_external_force_n.segment<3>(3 * row) += mass_kg * m_settings.gravity_m_per_s2;
}

namespace {

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
  changed();
  EnrichBatch batch;
  plan_cuts(cuts, batch);
  ++m_element_revision;

  // The ghosts, vertex by vertex around the batch's tets.
  std::vector<int> vertices;
  for (const TetCut& cut : cuts) {
    for (const int v : m_mesh.tets[static_cast<size_t>(cut.tet)]) vertices.push_back(v);
  }
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  for (const int v : vertices) plan_ghosts(v, batch);
  check_offsets(offsets_m, batch);

  EnrichmentResult result;
  const std::uint64_t layout_before = m_tangent.layout_revision();
  const int u_rows = m_dofs.free_vertex_count();
  batch.old_dofs = enriched_dof_count();
  const int first_new_cut_tet = m_xfem.cut_tet_count();
  std::vector<std::pair<int, int>> new_blocks;  // (row, column) the new cut tets couple
  m_orphaned_rows.clear();
  m_arrivals.clear();
  append_ghost_rows(batch);
  m_held_copies.insert(m_held_copies.end(), batch.new_held.begin(), batch.new_held.end());
  m_new_row_start_m.assign(batch.new_rows.size(), std::nullopt);
  for (size_t c = 0; c < batch.plans.size(); ++c) {
    const size_t piece_count = batch.plans[c].geometry.pieces.size();
    std::vector<CutPiece> pieces(piece_count);
    std::vector<Eigen::Matrix3d> rotations(piece_count, m_elasticity.rotation(batch.plans[c].tet));
    start_pieces(batch, c, offsets_m, displacement_m, pieces, rotations);
    const int k = replace_cut_tet(batch, c, pieces, rotations);
    list_coupled_blocks(k, new_blocks);
  }
  insert_coupled_blocks(new_blocks, first_new_cut_tet);
  // An orphan that a later cut tet of the batch took up again is no orphan.
  std::erase_if(m_orphaned_rows,
                [&](int row) { return row >= u_rows && m_ghost_users[static_cast<size_t>(row - u_rows)] != 0; });
  orphan_unused_vertex_rows(batch);
  result.new_cut_tets = static_cast<int>(batch.plans.size());
  result.new_enriched_dofs = enriched_dof_count() - batch.old_dofs;

  // 5. Slots: of the new cut tets only, unless the storage moved (a row outgrew its room).
  result.matrix_relayout = m_tangent.layout_revision() != layout_before;
  if (result.matrix_relayout) {
    refresh_all_slots(m_tangent.layout_revision() == layout_before + 1);
  } else {
    for (int k = first_new_cut_tet; k < m_xfem.cut_tet_count(); ++k) refresh_cut_tet_slots(k);
  }
  // 6. The blocks only retired cut tets used are zeros the product would multiply every step (40%
  // of the blocks after 30 + 30 careless strokes; docs/BENCHMARKS.md): gone once the retired slots
  // reach RETIRED_SLOT_SHARE_TO_COMPACT of the blocks.
  if (static_cast<double>(m_retired_slots) >= RETIRED_SLOT_SHARE_TO_COMPACT * m_tangent.nonzero_blocks()) {
    if (drop_retired_blocks()) result.matrix_relayout = true;
  }
  return result;
}

// Every cut's geometry first: nothing changes before all are known to be valid.
void DeformableBody::plan_cuts(std::span<const TetCut> cuts, EnrichBatch& batch) const {
  std::vector<EnrichBatch::Plan>& plans = batch.plans;
  std::vector<int>& plan_of_tet = batch.plan_of_tet;
  plan_of_tet.assign(static_cast<size_t>(m_mesh.tet_count()), -1);
  for (size_t c = 0; c < cuts.size(); ++c) {
    EnrichBatch::Plan plan;
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
}

// The offsets given for the cut tets to make, one list per cut tet and one set per piece.
void DeformableBody::check_offsets(std::span<const std::vector<TetPositions>> offsets_m, const EnrichBatch& batch) {
  const std::vector<EnrichBatch::Plan>& plans = batch.plans;
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
}

// 1. The new ghosts' rows, their mass, damping and external force zero.
void DeformableBody::append_ghost_rows(const EnrichBatch& batch) {
  const int u_rows = m_dofs.free_vertex_count();
  const int old_dofs = batch.old_dofs;
  const std::vector<SeparatingCuts>& new_rows = batch.new_rows;
  const std::vector<int>& new_row_vertex = batch.new_row_vertex;
  for (size_t n = 0; n < new_rows.size(); ++n) {
    const int vertex = new_row_vertex[n];
    const int k = enriched_dof_count();
    const int row = m_tangent.append_block_row(m_enriched_row_capacity[static_cast<size_t>(vertex)]);
    if (row != u_rows + k) throw std::logic_error("enrich: the tangent's rows and the unknowns disagree");
    m_enriched_dofs.push_back(EnrichedDof{vertex, new_rows[n].cut_id[0], new_rows[n].side[0], row, new_rows[n]});
    m_next_enriched_dof.push_back(m_first_enriched_dof[static_cast<size_t>(vertex)]);
    m_first_enriched_dof[static_cast<size_t>(vertex)] = k;
  }
  m_ghost_users.resize(static_cast<size_t>(enriched_dof_count()), 0);
  m_mass_kg.conservativeResize(dof_count());
  m_mass_damping_kg_per_s.conservativeResize(dof_count());
  m_external_force_n.conservativeResize(dof_count());
  m_mass_kg.tail(3 * (enriched_dof_count() - old_dofs)).setZero();
  m_mass_damping_kg_per_s.tail(3 * (enriched_dof_count() - old_dofs)).setZero();
  m_external_force_n.tail(3 * (enriched_dof_count() - old_dofs)).setZero();
}

// 2. The pieces of plan c: their rows, and where each starts: where its parent had the vertex. A new
// ghost starts as a copy of the copy the first piece using it comes from (m_new_row_start_m); a
// piece that comes from another copy than the row it uses is listed in m_arrivals (its momentum).
void DeformableBody::start_pieces(const EnrichBatch& batch, size_t c,
                                  std::span<const std::vector<TetPositions>> offsets_m,
                                  const Eigen::VectorXd* displacement_m, std::vector<CutPiece>& pieces,
                                  std::vector<Eigen::Matrix3d>& rotations) {
  const EnrichBatch::Plan& plan = batch.plans[c];
  const int old = plan.old;
  const CutTetGeometry& geometry = plan.geometry;
  const int u_rows = m_dofs.free_vertex_count();
  const int first_new_row = u_rows + batch.old_dofs;
  const Tet& tet = m_mesh.tets[static_cast<size_t>(plan.tet)];
  const double mass_kg = tet_mass_kg(m_elasticity.rest(plan.tet));
  // The current value of an existing row (zero without a running state), or a new row's start.
  const auto current = [&](int row) -> Eigen::Vector3d {
    if (row >= first_new_row) {
      return m_new_row_start_m[static_cast<size_t>(row - first_new_row)].value_or(Eigen::Vector3d::Zero());
    }
    if (displacement_m == nullptr || 3 * row >= displacement_m->size()) return Eigen::Vector3d::Zero();
    return displacement_m->segment<3>(3 * row);
  };
  const auto row_of = [&](int planned) {
    return planned >= -1 || is_held_copy(planned) ? planned : first_new_row + (-2 - planned);
  };
  for (size_t q = 0; q < pieces.size(); ++q) {
    CutPiece& piece = pieces[q];
    piece.weight = geometry.pieces[q].volume_fraction;
    const int parent_index = plan.from_cut ? geometry.pieces[q].parent : static_cast<int>(q);
    const CutPiece* parent = old >= 0 ? &m_xfem.piece(old, parent_index) : nullptr;
    if (old >= 0) rotations[q] = m_xfem.rotation(old, parent_index);
    for (size_t j = 0; j < 4; ++j) {
      // The copy the piece's material at vertex j comes from, and its displacement there.
      const bool from_ghost = parent != nullptr && parent->ghost_row[j] >= 0;
      const int from_row = from_ghost ? parent->ghost_row[j] : vertex_block_row(tet[j]);
      Eigen::Vector3d from_m = from_row >= 0 ? current(from_row) : Eigen::Vector3d::Zero();
      if (from_ghost) from_m -= parent->offset_m[j];
      const int planned = row_of(plan.rows[q][j]);
      const int row = planned >= 0 ? planned : vertex_block_row(tet[j]);
      if (row >= first_new_row) {
        std::optional<Eigen::Vector3d>& start = m_new_row_start_m[static_cast<size_t>(row - first_new_row)];
        if (!start) start = from_m;
      }
      if (row >= 0 && row != from_row) m_arrivals.push_back({row, from_row, 0.25 * piece.weight * mass_kg});
      if (planned == -1) continue;  // the real vertex
      piece.ghost_row[j] = planned;
      if (planned < 0) continue;  // a held copy: at the fixed vertex's rest position
      piece.offset_m[j] = offsets_m.empty() ? Eigen::Vector3d(current(planned) - from_m) : offsets_m[c][q][j];
    }
  }
}

// 3. Mass and external force: the retired cut tet's share leaves its ghosts, the new one's arrives.
// Returns the new cut tet.
int DeformableBody::replace_cut_tet(EnrichBatch& batch, size_t c, const std::vector<CutPiece>& pieces,
                                    const std::vector<Eigen::Matrix3d>& rotations) {
  EnrichBatch::Plan& plan = batch.plans[c];
  const int old = plan.old;
  CutTetGeometry& geometry = plan.geometry;
  const Tet& tet = m_mesh.tets[static_cast<size_t>(plan.tet)];
  const int u_rows = m_dofs.free_vertex_count();
  if (old >= 0) {
    add_piece_loads(old, -1.0);
    for (const int slot : m_xfem.slots(old)) m_retired_slots += slot >= 0 ? 1 : 0;
    m_xfem.retire(old);
  } else {
    // The uncut tet's share leaves its vertices (its pieces bring theirs back below).
    const TetRest& rest = m_elasticity.rest(plan.tet);
    for (const int v : tet) {
      const int row = vertex_block_row(v);
      if (row >= 0) add_row_load(row, -0.25 * tet_mass_kg(rest), mass_damping_per_s(rest));
    }
    m_elasticity.exclude(plan.tet);
    ++m_tets_cut;
  }
  CutTet cut_tet;
  cut_tet.cut = geometry.cuts.front();
  cut_tet.vertices = tet;
  cut_tet.rest_m = m_mesh.rest_corners(plan.tet);
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
  add_piece_loads(k, 1.0);
  // A piece of held material (every node a fixed vertex or a held copy) has no unknowns and stays at
  // rest: it adds nothing, as a parked piece (its cut faces face held material only).
  for (int p = 0; p < static_cast<int>(m_xfem.piece_count(k)); ++p) {
    const std::array<int, 4> rows = piece_rows(k, p);
    if (std::all_of(rows.begin(), rows.end(), [](int row) { return row < 0; })) m_xfem.park(k, p);
  }
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
  return k;
}

// A free vertex's own row that no element uses any more (no uncut tet around it, no piece in which
// it is real: every piece at its corner went to a ghost) is an orphan as a ghost no piece uses: it
// keeps its vertex's mass so the system stays regular, loses its load and stops. It never serves
// again (pieces only split further). Seen once in 30 + 30 careless strokes through the frog: its
// mass had cancelled to -7e-21 kg and Jacobi refused the system.
void DeformableBody::orphan_unused_vertex_rows(const EnrichBatch& batch) {
  for (const EnrichBatch::Plan& plan : batch.plans) {
    for (const int v : m_mesh.tets[static_cast<size_t>(plan.tet)]) {
      const int row = vertex_block_row(v);
      if (row < 0) continue;
      bool used = false;
      for (int s = m_adjacency.vertex_tets_begin[static_cast<size_t>(v)];
           s < m_adjacency.vertex_tets_begin[static_cast<size_t>(v) + 1] && !used; ++s) {
        const int t = m_adjacency.vertex_tets[static_cast<size_t>(s)];
        const int k = cut_tet_index(t);
        if (k < 0) {
          used = true;
          break;
        }
        const Tet& tet = m_mesh.tets[static_cast<size_t>(t)];
        const auto local = static_cast<size_t>(std::find(tet.begin(), tet.end(), v) - tet.begin());
        for (int p = 0; p < static_cast<int>(m_xfem.piece_count(k)) && !used; ++p) {
          used = m_xfem.piece(k, p).ghost_row[local] < 0;
        }
      }
      if (used) continue;
      m_mass_kg.segment<3>(3 * row).setConstant(m_vertex_mass_kg[static_cast<size_t>(v)]);
      m_mass_damping_kg_per_s.segment<3>(3 * row).setConstant(m_vertex_mass_damping_kg_per_s[static_cast<size_t>(v)]);
      m_external_force_n.segment<3>(3 * row).setZero();
      if (std::find(m_orphaned_rows.begin(), m_orphaned_rows.end(), row) == m_orphaned_rows.end()) {
        m_orphaned_rows.push_back(row);
      }
    }
  }
}

// 4. The blocks the pieces of cut tet k couple beyond u-u (which exist already).
void DeformableBody::list_coupled_blocks(int k, std::vector<std::pair<int, int>>& new_blocks) const {
  const int dofs = m_xfem.dof_count(k);
  std::vector<std::uint8_t> coupled;
  m_xfem.coupled_dofs(k, coupled);
  for (int r = 0; r < dofs; ++r) {
    for (int col = 0; col < dofs; ++col) {
      if (r < 4 && col < 4) continue;
      if (coupled[static_cast<size_t>(dofs * r + col)] == 0) continue;  // identically zero
      const int row = cut_tet_dof_row(k, r);
      const int column = cut_tet_dof_row(k, col);
      if (row < 0 || column < 0) continue;  // a fixed vertex's u
      new_blocks.emplace_back(row, column);
    }
  }
}

// The batch's new blocks: room for all of them at once (rows start compact, MatrixReserve), then in.
// The rows around the cut tets also get a cut's room (their ghost room, as an enriched row's): those
// of their stars' vertices, and when that needs a re-layout, those within CUT_ROOM_RINGS of them, so
// that the next strokes of a blade moving on find it: a re-layout every few steps of a stroke, not
// one per step.
void DeformableBody::insert_coupled_blocks(std::vector<std::pair<int, int>>& new_blocks, int first_new_cut_tet) {
  std::sort(new_blocks.begin(), new_blocks.end());
  new_blocks.erase(std::unique(new_blocks.begin(), new_blocks.end()), new_blocks.end());
  std::map<int, int> extra_of_row;
  for (const auto& [row, column] : new_blocks) {
    if (m_tangent.find_slot(row, column) < 0) ++extra_of_row[row];
  }
  std::vector<int> ring;  // the vertices of the new cut tets, then the rings around them
  for (int k = first_new_cut_tet; k < m_xfem.cut_tet_count(); ++k) {
    for (const int v : m_xfem.cut_tets()[static_cast<size_t>(k)].vertices) ring.push_back(v);
  }
  std::vector<std::uint8_t> reached(static_cast<size_t>(m_mesh.vertex_count()), 0);
  for (const int v : ring) reached[static_cast<size_t>(v)] = 1;
  const auto lacks_room = [&] {
    return std::any_of(extra_of_row.begin(), extra_of_row.end(), [&](const std::pair<const int, int>& row_extra) {
      return m_tangent.row_size(row_extra.first) + row_extra.second > m_tangent.row_capacity(row_extra.first);
    });
  };
  const auto give_room = [&](int w) {
    const int row = vertex_block_row(w);
    if (row < 0) return;
    const int room = m_enriched_row_capacity[static_cast<size_t>(w)] - m_tangent.row_size(row);
    int& extra = extra_of_row[row];
    extra = std::max(extra, room);
  };
  for (const int v : ring) give_room(v);
  for (int rings = 1; rings <= CUT_ROOM_RINGS && !ring.empty(); ++rings) {
    if (rings == 2 && !lacks_room()) break;  // the stars have room: no re-layout, so none wider
    std::vector<int> next;
    for (const int v : ring) {
      const auto first = static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v)]);
      const auto end = static_cast<size_t>(m_adjacency.vertex_tets_begin[static_cast<size_t>(v) + 1]);
      for (size_t e = first; e < end; ++e) {
        for (const int w : m_mesh.tets[static_cast<size_t>(m_adjacency.vertex_tets[e])]) {
          if (reached[static_cast<size_t>(w)] != 0) continue;
          reached[static_cast<size_t>(w)] = 1;
          next.push_back(w);
          give_room(w);
        }
      }
    }
    ring = std::move(next);
  }
  m_tangent.reserve_room(std::vector<std::pair<int, int>>(extra_of_row.begin(), extra_of_row.end()));
  for (const auto& [row, column] : new_blocks) m_tangent.insert_block(row, column);
}

}  // namespace tissue
