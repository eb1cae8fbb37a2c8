// DeformableBody: a tet mesh made into a DynamicsModel: co-rotational elasticity, lumped mass,
// Rayleigh damping, gravity and fixed vertices (removed from the unknowns); XFEM cuts that grow the
// system in place; and the force terms attached to it (system/force_term.hpp: the god-object
// contact's spring).
//
// Unknowns (3 each): block rows [0, free_vertex_count()) are the displacements u of the free
// vertices, in vertex order; then come the enriched unknowns a, one per ghost key (vertex, the cuts
// that separate the piece from it: for a single cut (vertex, cut id, side)), in creation order. A
// fixed vertex has no u row but gets an enriched row when cut: its ghost copy on the other side of
// the cut must be free to move, unless the copy's pieces touch held material (a tet whose four
// vertices are fixed): then it is a held copy, at rest with no row (HELD_COPY_FIRST).
#pragma once

#include "core/fem/body_parts.hpp"
#include "core/fem/corotational.hpp"
#include "core/fem/tet_cut.hpp"
#include "core/fem/tet_pieces.hpp"
#include "core/fem/xfem_elasticity.hpp"
#include "core/material/material.hpp"
#include "core/mesh/tet_mesh.hpp"
#include "core/mesh/topology.hpp"
#include "core/system/assembly.hpp"
#include "core/system/block_sparse_matrix.hpp"
#include "core/system/dynamics_model.hpp"
#include "core/system/force_term.hpp"
#include "core/system/rayleigh_damping.hpp"
#include "core/system/rows_left.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace tissue {

struct BodySettings {
  /// The material of every region the mesh file gives none and `region_materials` does not set.
  Material material;
  /// Materials set by region name (TetMesh::regions), replacing the file's (resolve_region_materials).
  std::vector<RegionMaterial> region_materials;
  /// How the tets answer (issue 25): co-rotational linear (the default) or stable Neo-Hookean.
  MaterialModel material_model = MaterialModel::corotational_linear;
  RayleighDamping damping;
  Eigen::Vector3d gravity_m_per_s2{0.0, -9.81, 0.0};
  std::vector<int> fixed_vertices;  ///< 0-based; they keep their rest positions
  BlockSparseMatrix::Reserve reserve;
  RotationSettings rotation;  ///< when the per-tet rotation extraction stops (accuracy)
};

/// The cuts that separate a piece from one of its tet's vertices: (cut id, H of the vertex for
/// that cut) pairs, sorted by cut id. With the vertex it keys the piece's ghost copy of the vertex,
/// shared by the pieces of neighbouring tets on the same sides (issue 21).
struct SeparatingCuts {
  int count = 0;
  std::array<int, MAX_PIECE_CUTS> cut_id{};
  std::array<std::int8_t, MAX_PIECE_CUTS> side{};
  bool operator==(const SeparatingCuts&) const = default;
};

/// One enriched unknown a (3 components, one block row): the ghost copy of a vertex, listed once per
/// (vertex, separating cuts), however many cut tets share it (dissertation figure 4.2).
struct EnrichedDof {
  int vertex = -1;
  int cut_id = 0;        ///< the first separating cut (a single cut: the cut)
  std::int8_t side = 0;  ///< H of the vertex for that cut: +1 above, -1 below
  int row = -1;          ///< block row in the system (unknowns 3 row .. 3 row + 2)
  SeparatingCuts separated_by;
};

/// How one cut tet is cut: its cuts in the order applied and its pieces (piece p is
/// XfemElasticity::piece(k, p)).
struct CutTetGeometry {
  std::vector<TetCut> cuts;
  std::vector<TetPiece> pieces;
  /// Per cut, its plane (cut_plane; a cut given without its crossings, as in tests, through the
  /// middles of the edges it crosses): what tells which face material a piece has.
  std::vector<CutPlane> planes;
};

/// The tangent drops the blocks only retired cut tets used once the slots of the cut tets retired
/// since it last did reach this share of its blocks (DeformableBody::enrich).
inline constexpr double RETIRED_SLOT_SHARE_TO_COMPACT = 0.25;

/// ... and packs its rows back to back (BlockSparseMatrix::RowRoom::packed) when the room the rows
/// take is more than this many times their blocks: the cuts' room (CUT_ROOM_RINGS, doubled at each
/// re-layout) grew to 20 times the blocks after the extremes suite's 30 + 30 strokes (852k slots for
/// 42k blocks), and the step's passes over the blocks ran through 61 MB (docs/BENCHMARKS.md).
inline constexpr double ROW_ROOM_PER_BLOCK_TO_PACK = 4.0;

/// When a cut must re-lay the tangent out (a row near it lacks room), the rows of the vertices within
/// this many rings (vertex - tet - vertex) of its cut tets get a cut's room in the same re-layout, so
/// that the blade moving on finds room for the next steps: a stroke through the frog re-laid the
/// storage out at 34 of its 43 cutting steps with the two rings its tets' stars reach.
inline constexpr int CUT_ROOM_RINGS = 4;

/// What an enrichment changed.
struct EnrichmentResult {
  int new_cut_tets = 0;          ///< cut tets made (one per cut, and those remade with other ghosts)
  int new_enriched_dofs = 0;     ///< new block rows (3 unknowns each), appended at the end
  bool matrix_relayout = false;  ///< the tangent's storage was re-laid out (layout_revision() changed)
};

class DeformableBody final : public DynamicsModel {
 public:
  /// Throws ParameterError for invalid settings (material, damping, non-finite gravity,
  /// fixed vertex ids out of range).
  DeformableBody(TetMesh mesh, BodySettings settings);

  [[nodiscard]] int dof_count() const override { return 3 * (m_dofs.free_vertex_count() + enriched_dof_count()); }
  [[nodiscard]] const Eigen::VectorXd& mass_kg() const override { return m_mass_kg; }
  [[nodiscard]] const Eigen::VectorXd& mass_damping_kg_per_s() const override { return m_mass_damping_kg_per_s; }
  [[nodiscard]] double stiffness_damping_s() const override { return m_settings.damping.stiffness_damping_s; }
  [[nodiscard]] const Eigen::VectorXd& external_force_n() const override { return m_external_force_n; }
  void evaluate(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n, bool update_tangent) override {
    evaluate_pass(displacement_m, internal_force_n, update_tangent, /*with_potential=*/false, ExtractInto::own);
  }
  /// The elements' energies are summed in the same pass (4-7% of it; docs/DESIGN.md, "Backward Euler
  /// on steps that turn elements far").
  void evaluate_with_potential(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n,
                               bool update_tangent) override {
    evaluate_pass(displacement_m, internal_force_n, update_tangent, /*with_potential=*/true, ExtractInto::own);
  }
  /// The rotations go beside the elements' own (ExtractInto::ahead) and are swapped in when taken.
  /// Declined while an attached force term is not idle, and when the body was cut since the last
  /// call: a stroke under way cuts the next step too, which could not take it (the caller's energy
  /// pass, without the forces and the tangent, is cheaper; the first step after the stroke
  /// evaluates its start itself).
  bool evaluate_ahead(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n) override;
  bool take_evaluation_ahead(const Eigen::VectorXd& displacement_m) override;
  /// The uncut tets' forces and blocks are then assembled by the team (bitwise the same result).
  void lend_work_team(WorkTeam* team) override { m_team = team; }
  [[nodiscard]] const BlockSparseMatrix& tangent() const override { return m_tangent; }
  /// A vertex's frame is the rotation nearest the sum of the rotations of its tets not modelled by
  /// XFEM (identity if it has none); an enriched unknown takes its vertex's. O(tets), on request.
  [[nodiscard]] const std::vector<Eigen::Matrix3d>* block_frames() const override;
  /// A free vertex's row: X + u; an enriched unknown's: its vertex's X plus the unknown. O(unknowns).
  [[nodiscard]] const std::vector<Eigen::Vector3d>* block_positions(const Eigen::VectorXd& displacement_m) const override;
  /// First a bound, O(unknowns): no element (or cut part) turns further than 12 max|block of the
  /// increment| max|grad(phi)|; past `resolution_rad`, each tet and part: |axial(skew(R^T G))| with
  /// G the gradient of the increment and R its rotation at the last evaluate(), a part's times the
  /// square root of its share w of its tet's volume: the force by which a linearized step strays is
  /// ~ V theta^2, so a part turning theta strays as a whole tet turning sqrt(w) theta (a sliver at a
  /// cut's front spinning fast no longer sets off a Newton correction of the whole body).
  [[nodiscard]] double largest_turn_rad(const Eigen::VectorXd& increment_m, double resolution_rad) const override;
  /// Both turns as largest_turn_rad() answers each, in one pass over the elements where both pass
  /// their bounds.
  [[nodiscard]] std::array<double, 2> largest_turns_rad(const Eigen::VectorXd& first_m, const Eigen::VectorXd& second_m,
                                                        std::array<double, 2> resolution_rad) const override;
  /// Each uncut tet and live cut piece measured as largest_turn_rad() measures it past its bound.
  void mark_turning_rows(const Eigen::VectorXd& increment_m, double angle_rad,
                         std::vector<std::uint8_t>& turning) const override;
  /// elastic_energy_j + the attached terms' energies - f_ext . u. [J]
  [[nodiscard]] double potential_energy_j(const Eigen::VectorXd& displacement_m) override;
  [[nodiscard]] double kept_potential_energy_j(const Eigen::VectorXd& displacement_m) const override;
  /// The same sum at the last evaluate_with_potential()'s displacement, made in that pass (NaN after
  /// a plain evaluate(), a cut, a part parked, a term attached or detached; a term's own parameters
  /// changed since are not in it: read it right after the evaluate).
  [[nodiscard]] double potential_energy_at_last_evaluate_j() const override { return m_evaluated_potential_j; }

  [[nodiscard]] const TetMesh& mesh() const { return m_mesh; }
  /// The mesh's faces, edges and vertex stars (build_adjacency), made once here.
  [[nodiscard]] const TetAdjacency& adjacency() const { return m_adjacency; }
  [[nodiscard]] const DofMap& dofs() const { return m_dofs; }
  [[nodiscard]] const BodySettings& settings() const { return m_settings; }
  [[nodiscard]] const CorotationalElasticity& elasticity() const { return m_elasticity; }
  /// The material of each mesh region, resolved (TetRest::material indexes them).
  [[nodiscard]] const std::vector<Material>& materials() const { return m_materials; }
  /// Each region's mass damping alpha [1/s], resolved: its material's, else the body's (settings().damping).
  [[nodiscard]] const std::vector<double>& region_mass_damping_per_s() const { return m_region_mass_damping_per_s; }
  [[nodiscard]] const std::vector<double>& vertex_masses_kg() const { return m_vertex_mass_kg; }
  [[nodiscard]] double total_mass_kg() const;

  /// Current (real) positions of all vertices (3 per vertex) for a displacement of the unknowns.
  void positions(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& positions_m) const;

  // --- XFEM cuts (dissertation 3.3, 4.2; docs/DESIGN.md, "Cutting") ---

  /// Enriches completely cut tets and grows the system in place: ghost unknowns are appended
  /// (listed once per ghost key), their blocks inserted into the tangent's reserved room (the u-u
  /// blocks and their slots are kept), mass and external force moved to the rows that carry them. A
  /// tet cut before is cut again (issue 21): its pieces are split by the new cut (split_pieces), the
  /// old cut tet is retired and a new one of the new pieces appended, each starting where its parent
  /// piece was. A ghost is a copy of a vertex with a displacement of its own (xfem_elasticity.hpp).
  /// Throws ParameterError, with nothing changed, if a cut names a tet out of range, twice in the
  /// batch, already cut by the same cut id or by MAX_PIECE_CUTS cuts, lacks a sign or has a sign
  /// other than +-1, has a volume fraction outside (0, 1) or not finite, or (cutting a cut tet) lacks
  /// the edge crossings of a plane.
  ///
  /// Around each vertex of the cut tets, the pieces that the same cuts separate from it and that
  /// touch across faces share one ghost (the virtual-node algorithm's copies): a cut tet whose
  /// pieces move to other ghosts is made again too (EnrichmentResult::new_cut_tets counts every cut
  /// tet made: the cuts' first, in order, then those).
  ///
  /// This form is for a body at rest (u = 0: new ghosts start at zero, grow_state()), or to replay
  /// recorded cuts: `offsets_m`, empty or at least one list per cut tet made, are the offsets of its
  /// pieces (CutPiece::offset_m) when it was made, and the recorded state replaces the grown one.
  EnrichmentResult enrich(std::span<const TetCut> cuts, std::span<const std::vector<TetPositions>> offsets_m = {});
  EnrichmentResult enrich(const TetCut& cut) { return enrich(std::span<const TetCut>(&cut, 1)); }

  /// The form for a running body (a cut in the middle of a simulation): `state` is grown, each new
  /// ghost starting as a copy of the copy it splits from (its displacement and velocity), so the
  /// cut moves nothing and keeps the momentum. A piece that joins a ghost which exists already (made
  /// by a tet completed at an earlier step, and moved since) records an offset so that it starts
  /// where the tet (or its parent piece) was, and brings its momentum (an inelastic join: momentum
  /// kept, kinetic energy not gained). Throws ParameterError for bad cuts and std::invalid_argument
  /// for a state of the wrong size, with nothing changed.
  EnrichmentResult enrich(std::span<const TetCut> cuts, DynamicState& state);

  /// Grows a state to dof_count() in place: existing entries unchanged, new ones (the ghosts'
  /// displacements and velocities) zero. Call after enrich() without a state.
  void grow_state(DynamicState& state) const;

  [[nodiscard]] int enriched_dof_count() const { return static_cast<int>(m_enriched_dofs.size()); }
  [[nodiscard]] const std::vector<EnrichedDof>& enriched_dofs() const { return m_enriched_dofs; }
  /// The held copies, in creation order (row: HELD_COPY_FIRST + index): copies of fixed vertices
  /// whose pieces touch held material, a tet whose four vertices are fixed (or an uncut one of them
  /// across a face around the vertex). Material the fixed region holds stays held when cut.
  [[nodiscard]] const std::vector<EnrichedDof>& held_copies() const { return m_held_copies; }
  /// Whether tet t is held material: its four vertices fixed.
  [[nodiscard]] bool held_tet(int t) const;
  /// The cuts that separate a piece's copy of a vertex from it, by CutPiece::ghost_row: a ghost
  /// row's or a held copy's (none for -1, the real vertex).
  [[nodiscard]] const SeparatingCuts& copy_separated_by(int ghost_row) const;
  /// Index into enriched_dofs() of the unknown of (vertex, cut id, side) of a single cut, or -1.
  [[nodiscard]] int find_enriched_dof(int vertex, int cut_id, int side) const;
  /// Index into enriched_dofs() of the ghost of `vertex` behind `cuts`, or -1.
  [[nodiscard]] int find_ghost(int vertex, const SeparatingCuts& cuts) const;
  /// Every cut tet made, retired ones included (a tet cut again is a new cut tet).
  [[nodiscard]] const std::vector<CutTet>& cut_tets() const { return m_xfem.cut_tets(); }
  /// How many tets are cut.
  [[nodiscard]] int cut_tet_count() const { return m_tets_cut; }
  /// How cut tet k is cut (its cuts and pieces).
  [[nodiscard]] const CutTetGeometry& cut_geometry(int k) const { return m_cut_geometry.at(static_cast<size_t>(k)); }
  /// Drops from the tangent the XFEM blocks (a ghost row or column) that no live cut tet's unparked
  /// piece uses (those only retired cut tets or parked pieces used: zeros the product multiplies
  /// every step) and looks every slot up again; returns whether any went (the tangent's layout
  /// changed). enrich() does it itself once the retired cut tets' slots reach
  /// RETIRED_SLOT_SHARE_TO_COMPACT of the blocks, park_parts_outside() whenever it parks. Packs the
  /// rows too (BlockSparseMatrix::RowRoom::packed) when their room passes ROW_ROOM_PER_BLOCK_TO_PACK
  /// times their blocks, or always if asked (then returns true when a row moved, even if no block
  /// went). The forces are unchanged, bitwise; so is the product when no block went.
  enum class PackRows { when_sparse, always };
  bool drop_retired_blocks(PackRows pack = PackRows::when_sparse);
  // --- Parts out of the dynamics ---

  /// Takes out of the dynamics every part of the body (find_body_parts) that no fixed vertex holds
  /// and whose block rows' points all lie outside `field` (their bounding box misses it): a piece cut
  /// free that fell out of the operating field. Its uncut tets and cut pieces add no force, block or
  /// energy from now on, its XFEM blocks leave the tangent, and each of its rows keeps its mass and
  /// weight only, so it falls on freely; each row's velocity becomes the part's mean velocity
  /// (momentum kept, its spin and vibration dropped), so that it falls as one rigid body. Parked
  /// rows stay parked (a later cut of a parked tet makes live pieces, which a later call parks
  /// again). Returns the rows this call parked, ascending. O(elements + unknowns).
  std::vector<int> park_parts_outside(const Eigen::AlignedBox3d& field, DynamicState& state);
  /// What park_parts_outside does to the rows it chose, velocities aside (a replay's: the recorded
  /// state follows). Throws std::invalid_argument, nothing changed, for a row out of range.
  void park_rows(std::span<const int> rows);
  /// Whether block row `row` belongs to a part taken out of the dynamics.
  [[nodiscard]] bool parked(int row) const { return row_left(&m_row_parked, row); }
  [[nodiscard]] int parked_row_count() const { return m_parked_rows; }
  /// The parked rows (DynamicsModel::rows_left).
  [[nodiscard]] const std::vector<std::uint8_t>* rows_left() const override { return &m_row_parked; }
  /// The parts the elements join the rows into (find_body_parts), found again only after a cut
  /// changed the elements (parking does not change how they join).
  [[nodiscard]] const BodyParts& body_parts() const;
  [[nodiscard]] const std::vector<int>* row_parts() const override { return &body_parts().part_of_row; }

  /// Whether cut tet k was replaced by a later cut of its tet (then it adds nothing).
  [[nodiscard]] bool retired(int k) const { return m_xfem.retired(k); }
  /// Index into cut_tets() of a tet's current cut tet, or -1 if it is not cut.
  [[nodiscard]] int cut_tet_index(int tet) const { return m_cut_index[static_cast<size_t>(tet)]; }
  [[nodiscard]] const XfemElasticity& xfem() const { return m_xfem; }

  /// Positions of the 4 vertices of piece `piece` of cut tet `cut_tet_index` (index into cut_tets()):
  /// the real vertices in the piece, the ghost copies elsewhere. [m]
  [[nodiscard]] TetPositions piece_positions(const Eigen::VectorXd& displacement_m, int cut_tet_index, int piece) const;
  /// The block rows of a piece's four nodes: its ghost's, or the vertex's own (-1: a fixed vertex).
  [[nodiscard]] std::array<int, 4> piece_rows(int cut_tet_index, int piece) const;
  /// Rest mass of a piece, rho w_p V. [kg]
  [[nodiscard]] double piece_mass_kg(int cut_tet_index, int piece) const;
  /// The same for a tet cut once: part a is piece 0, part b piece 1 (p_j = x_j, or the ghost X_j + c_j).
  [[nodiscard]] TetPositions part_positions(const Eigen::VectorXd& displacement_m, int cut_tet_index,
                                            CutPart part) const {
    return piece_positions(displacement_m, cut_tet_index, part == CutPart::above ? 0 : 1);
  }
  [[nodiscard]] double part_mass_kg(int cut_tet_index, CutPart part) const {
    return piece_mass_kg(cut_tet_index, part == CutPart::above ? 0 : 1);
  }

  // --- Force terms beside elasticity (the god-object contact's spring) ---

  /// evaluate() adds `term`'s force and stiffness from now on; the caller keeps it alive until
  /// detach(). Locates it in the tangent (ForceTerm::locate), and again after every re-layout.
  void attach(ForceTerm& term);
  /// Stops adding `term` (nothing if it is not attached).
  void detach(ForceTerm& term);
  [[nodiscard]] const std::vector<ForceTerm*>& force_terms() const { return m_force_terms; }
  void add_force_terms_tangent_product(const Eigen::VectorXd& vector, Eigen::VectorXd& product) const override {
    for (const ForceTerm* term : m_force_terms) {
      if (!term->idle()) term->add_tangent_product(vector, product);
    }
  }
  /// Where the mesh vertices sit in the tangent, for a term's checks and slots.
  [[nodiscard]] TermLayout term_layout() const { return {m_mesh.vertex_count(), m_dofs.vertex_row, &m_tangent}; }

  /// Forgets the rotation warm starts of all tets and parts (e.g. after a state was restored).
  void reset_rotations();
  /// The rotations, warm starts and turns before (the warm starts before the last extraction: the
  /// next starts from extrapolated_turn) of all tets and cut-tet pieces: with u, v they make the state
  /// a step continues from bitwise.
  struct Rotations {
    std::vector<Eigen::Matrix3d> tets;
    std::vector<Eigen::Quaterniond> tet_warm_starts;
    std::vector<Eigen::Quaterniond> tet_turns_before;
    std::vector<Eigen::Matrix3d> pieces;  ///< cut tet after cut tet, piece after piece
    std::vector<Eigen::Quaterniond> piece_warm_starts;
    std::vector<Eigen::Quaterniond> piece_turns_before;
  };
  void save_rotations(Rotations& rotations) const;
  /// Throws std::invalid_argument unless the sizes match the mesh and cuts and every rotation is one
  /// and every warm start a unit quaternion (is_rotation, is_unit_quaternion: a NaN warm start makes
  /// the next step's matrix NaN; found by fuzzing the FMU state).
  void check_rotations(const Rotations& rotations) const;
  /// check_rotations(), then takes them. Throws std::invalid_argument (nothing changed).
  void restore_rotations(const Rotations& rotations);
  /// Elastic energy at displacement u (cut tets: w_a E_a + w_b E_b). [J]
  [[nodiscard]] double elastic_energy_j(const Eigen::VectorXd& displacement_m);
  /// 1/2 v^T M v. [J]
  [[nodiscard]] double kinetic_energy_j(const Eigen::VectorXd& velocity_m_per_s) const;

 private:
  void evaluate_pass(const Eigen::VectorXd& displacement_m, Eigen::VectorXd& internal_force_n, bool update_tangent,
                     bool with_potential, ExtractInto into);
  /// potential_energy_j's sum from the elastic energy (m_positions_m set for `displacement_m`).
  [[nodiscard]] double potential_with_elastic_j(double elastic_energy_j, const Eigen::VectorXd& displacement_m) const;

  TetMesh m_mesh;
  TetAdjacency m_adjacency;         // faces and vertex stars, for grouping the pieces' ghosts
  std::vector<int> m_vertex_order;  // locality_order(): the block rows' and the assembly's sequence
  BodySettings m_settings;
  std::vector<Material> m_materials;                // per region
  std::vector<double> m_region_mass_damping_per_s;  // per region
  DofMap m_dofs;
  CorotationalElasticity m_elasticity;
  std::vector<double> m_vertex_mass_kg;
  std::vector<double> m_vertex_mass_damping_kg_per_s;  // alpha m, lumped as the mass
  Eigen::VectorXd m_mass_kg;
  Eigen::VectorXd m_mass_damping_kg_per_s;  // per unknown, as m_mass_kg
  Eigen::VectorXd m_external_force_n;
  BlockSparseMatrix m_tangent;
  std::vector<TetSlots> m_slots;
  Eigen::VectorXd m_positions_m;      // all vertices
  Eigen::VectorXd m_vertex_forces_n;  // all vertices

  [[nodiscard]] double density_kg_per_m3(const TetRest& rest) const {
    return m_materials[static_cast<size_t>(rest.material)].density_kg_per_m3;
  }
  // rho V of a tet (its material's density).
  [[nodiscard]] double tet_mass_kg(const TetRest& rest) const { return density_kg_per_m3(rest) * rest.volume_m3; }
  [[nodiscard]] double mass_damping_per_s(const TetRest& rest) const {
    return m_region_mass_damping_per_s[static_cast<size_t>(rest.material)];
  }

  // Looks up every slot held (uncut tets, cut tets, force terms) again: after a relayout.
  // All slots again after the tangent was re-laid out: by its slot map when it was re-laid out once
  // since they were right (`one_relayout`), else by search.
  void refresh_all_slots(bool one_relayout);
  /// A retired cut tet's slots are all -1 (it adds nothing; its blocks may be gone). `moved`: the
  /// tangent's relayout_slot_map() when it was re-laid out once since the table was right; a slot
  /// the map does not give (a table made since, still -1) is searched.
  void refresh_cut_tet_slots(int cut_tet_index, const std::vector<int>* moved = nullptr);
  /// The block row of local DOF `dof` of a cut tet (XfemElasticity::dof_count): u of a local vertex
  /// (-1 if fixed) or a ghost row.
  [[nodiscard]] int cut_tet_dof_row(int cut_tet_index, int dof) const;
  void check_cuts(std::span<const TetCut> cuts) const;
  EnrichmentResult enrich_pieces(std::span<const TetCut> cuts, std::span<const std::vector<TetPositions>> offsets_m,
                                 const Eigen::VectorXd* displacement_m);
  // enrich_pieces' stages, in order (deformable_body_enrich.cpp; the ghosts: deformable_body_ghosts.cpp),
  // and what they share (deformable_body_enrich.hpp).
  struct EnrichBatch;
  void plan_cuts(std::span<const TetCut> cuts, EnrichBatch& batch) const;
  void plan_ghosts(int v, EnrichBatch& batch) const;
  void collect_star_nodes(int v, std::span<const int> star, EnrichBatch& batch) const;
  void collect_star_faces(std::span<const int> star, EnrichBatch& batch) const;
  void join_star_pieces(std::span<const int> star, const std::vector<size_t>& members, EnrichBatch& batch) const;
  void assign_ghost_rows(int v, std::span<const int> star, const std::vector<size_t>& members,
                         EnrichBatch& batch) const;
  [[nodiscard]] bool touches_held_material(int v, std::span<const int> star, const std::vector<size_t>& members,
                                           int root, EnrichBatch& batch) const;
  [[nodiscard]] const SeparatingCuts& planned_copy_cuts(int ghost_row, const EnrichBatch& batch) const;
  static void check_offsets(std::span<const std::vector<TetPositions>> offsets_m, const EnrichBatch& batch);
  void append_ghost_rows(const EnrichBatch& batch);
  void start_pieces(const EnrichBatch& batch, size_t c, std::span<const std::vector<TetPositions>> offsets_m,
                    const Eigen::VectorXd* displacement_m, std::vector<CutPiece>& pieces,
                    std::vector<Eigen::Matrix3d>& rotations);
  int replace_cut_tet(EnrichBatch& batch, size_t c, const std::vector<CutPiece>& pieces,
                      const std::vector<Eigen::Matrix3d>& rotations);
  void list_coupled_blocks(int k, std::vector<std::pair<int, int>>& new_blocks) const;
  void insert_coupled_blocks(std::vector<std::pair<int, int>>& new_blocks, int first_new_cut_tet);
  void orphan_unused_vertex_rows(const EnrichBatch& batch);
  // Adds (sign +1) or removes (-1) what cut tet k's pieces put on the rows they use: rho w_p V / 4
  // of mass, its mass damping and its weight.
  void add_piece_loads(int k, double sign);
  // Adds a mass (negative: removes it) to a row with its mass damping alpha m and its weight m g.
  void add_row_load(int row, double mass_kg, double alpha_per_s);
  void check_unknowns(const Eigen::VectorXd& displacement_m) const;
  // largest_turn_rad's bound: 12 max|block of the increment| max|grad(phi)|. Checks the increment's size.
  [[nodiscard]] double turn_bound_rad(const Eigen::VectorXd& increment_m) const;
  // largest_turn_rad past its bound, every uncut tet and cut part, for one increment or two (a null
  // second: its entry 0) in one pass.
  [[nodiscard]] std::array<double, 2> largest_element_turns_rad(
      std::array<const Eigen::VectorXd*, 2> increments_m) const;
  // visit(rows, turn_rad) for the uncut tets at the co-rotational model's storage indices [first, end):
  // their four block rows (-1: a fixed vertex) and their turns by the increments (0 for a null one).
  template <class Visit>
  void for_each_tet_turn(size_t first, size_t end, std::array<const Eigen::VectorXd*, 2> increments_m,
                         Visit&& visit) const;
  // The same for each live cut piece not parked of the cut tets [first, end), its turns times the
  // square root of its volume share.
  template <class Visit>
  void for_each_piece_turn(size_t first, size_t end, std::array<const Eigen::VectorXd*, 2> increments_m,
                           Visit&& visit) const;
  [[nodiscard]] int vertex_block_row(int vertex) const { return m_dofs.vertex_row[static_cast<size_t>(vertex)]; }

  XfemElasticity m_xfem;
  std::vector<int> m_enriched_row_capacity;  // per vertex: blocks its enriched row is given
  std::vector<EnrichedDof> m_enriched_dofs;
  std::vector<EnrichedDof> m_held_copies;      // row: HELD_COPY_FIRST + index
  std::vector<CutTetGeometry> m_cut_geometry;  // per cut tet
  std::vector<int> m_ghost_users;              // per enriched unknown: pieces of live cut tets using it
  long m_retired_slots = 0;  // slots of the cut tets retired since the last compaction (shared ones counted again)
  std::vector<int> m_orphaned_rows;            // rows the last enrich() left unused
  // A piece's share at a vertex that the last enrich() moved to another copy (from_row -1: a fixed
  // vertex, at rest): its momentum goes with it.
  struct CopyArrival {
    int row;
    int from_row;
    double mass_kg;
  };
  std::vector<CopyArrival> m_arrivals;
  // Per ghost the last enrich() made: its start (set by the first piece that uses it).
  std::vector<std::optional<Eigen::Vector3d>> m_new_row_start_m;
  int m_tets_cut = 0;
  double m_largest_shape_gradient_per_m = 0.0;  // max |grad(phi_i)| over the mesh: 1 / the lowest altitude
  std::vector<int> m_first_enriched_dof;        // per vertex: first of its enriched unknowns, or -1
  std::vector<int> m_next_enriched_dof;         // per enriched unknown: next one of the same vertex, or -1
  std::vector<int> m_cut_index;                 // per tet: index into cut_tets(), or -1
  std::vector<std::uint8_t> m_row_parked;       // per block row (shorter: the rest are not parked)
  int m_parked_rows = 0;
  // body_parts(), found again only after a cut changed the elements: the union-find over the
  // organ's 52k tets is milliseconds, and the look every 10 steps should not be.
  mutable BodyParts m_parts;
  double m_evaluated_potential_j = std::numeric_limits<double>::quiet_NaN();  // at the last evaluate()
  // Moves on at every evaluate, enrich, park, re-layout, rotations' restore or reset and term
  // attached or detached; with the terms' own ForceTerm::revision, evaluation_revision().
  std::uint64_t m_changes = 1;
  [[nodiscard]] std::uint64_t evaluation_revision() const;
  struct EvaluationAhead {
    bool pending = false;
    std::uint64_t revision = 0;  // evaluation_revision() right after it
    Eigen::VectorXd displacement_m;
  };
  EvaluationAhead m_ahead;
  struct KeptPotential {  // the last potential_energy_j call
    double energy_j = std::numeric_limits<double>::quiet_NaN();
    std::uint64_t revision = 0;  // evaluation_revision() right after it
    Eigen::VectorXd displacement_m;
  };
  KeptPotential m_kept_potential;
  // What any change of the model does: the potential of the last evaluate is no longer the model's.
  void changed() {
    ++m_changes;
    m_evaluated_potential_j = std::numeric_limits<double>::quiet_NaN();
  }
  long m_element_revision = 0;  // counts enrichments
  long m_element_revision_at_ahead = 0;  // m_element_revision at the last evaluate_ahead call
  mutable long m_parts_revision = -1;    // m_element_revision when m_parts was found

  std::vector<ForceTerm*> m_force_terms;                // attached, not owned
  WorkTeam* m_team = nullptr;                           // lent for a step (lend_work_team)
  mutable std::vector<Eigen::Matrix3d> m_block_frames;  // block_frames(): made on request
  mutable std::vector<Eigen::Vector3d> m_block_positions;  // block_positions(): made on request
  mutable std::vector<Eigen::Matrix3d> m_vertex_frames;
  mutable std::vector<Eigen::Vector4d> m_vertex_turns;  // block_frames(): per vertex, its tets' quaternions summed
};

}  // namespace tissue
