// XFEM elasticity of completely cut tets (dissertation 3.3 and 4.2.1; docs/DESIGN.md, "Cutting"): a cut tet
// behaves as two full-shape co-rotational tets, part a above the cut (H = +1) and part b below
// (H = -1), weighted by their rest volume fractions w_a = V_a / V and w_b = 1 - w_a. Part p places
// local vertex j at p_pj = x_j + Psi_pj a_j with the shifted enrichment Psi_pj = (H_p - H_j) / 2
// (eq. 3.15, 3.26-3.27), has its own deformation gradient and its own rotation R_p (warm-started
// per part), and gives (eq. 3.31-3.32)
//   f_i   = w_a Fa_i + w_b Fb_i,   f^a_i = w_a Psi_ai Fa_i + w_b Psi_bi Fb_i,
//   Fp_i  = V R_p sigma(sym(R_p^T F_p) - I) g_i  (= [R_p K_e (R_p^T p_p - p0)]_i),
// with the tangent blocks of eq. 4.3-4.6, w_p s_p(I) s_p(J) R_p K_ij R_p^T, where s_p = 1 for a
// u unknown and Psi_pi for an enriched one.
//
// Internally a cut tet is a list of pieces (issue 21, the virtual-node algorithm of Molino et al.
// 2004): piece p is a full-shape copy weighted by w_p whose local vertex j is the real x_j, or a
// copy of it with its own unknown, the ghost row g: p_j = X_j + c_g - offset_j (X_j the rest
// position). A ghost is a displacement of its own, not a difference from u_j (issue 40): so a
// piece's lumped mass w_p m / 4 sits on exactly the rows that move it, and a piece cut free carries
// its own mass and its own weight, no more (the shifted enrichment a_j = u_j - c_g couples the two
// by an off-diagonal mass block that a diagonal lumping drops: a freed beam end fell at 8.5 m/s^2).
// A single cut is the two pieces above, and the forces and blocks below are eq. 3.31-3.32 and
// 4.3-4.6 in those variables. For N pieces: u_j gets w_p Fp_j of the pieces that use the real x_j,
// a ghost row w_p Fp_j of the pieces that use it, and block (I, J) sum_p w_p R_p K_ij R_p^T over the
// pieces that use both DOFs.
#pragma once

#include "core/fem/element_model.hpp"
#include "core/fem/rotation.hpp"
#include "core/fem/tet_cut.hpp"
#include "core/fem/tet_element.hpp"
#include "core/material/material.hpp"
#include "core/mesh/tet_mesh.hpp"
#include "core/system/block_sparse_matrix.hpp"
#include "core/system/work_team.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace tissue {

/// The two parts of a cut tet: part a lies above the cut (H = +1), part b below (H = -1).
enum class CutPart { above, below };

/// H of a part: +1 above, -1 below.
constexpr int part_side(CutPart part) { return part == CutPart::above ? 1 : -1; }

/// The shifted enrichment Psi_pi = (H_p - H_i) / 2 (eq. 3.15) of a vertex on side H_i in part p:
/// 0 on the part's own side, -H_i (that is +-1) on the other side.
constexpr double enrichment_shift(int vertex_side, CutPart part) {
  return 0.5 * static_cast<double>(part_side(part) - vertex_side);
}

/// One completely cut tet as the XFEM models it.
struct CutTet {
  TetCut cut;                         ///< as the cutter gave it (tet, cut id, sides H_i, fraction, edge ratios)
  Tet vertices{};                     ///< mesh vertex of each local vertex
  double weight_above = 0.5;          ///< w_a = V_a / V
  double weight_below = 0.5;          ///< w_b = 1 - w_a
  /// Rest positions X_j of the local vertices (a ghost's position is X_j + c_g - offset_j).
  TetPositions rest_m{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                      Eigen::Vector3d::Zero()};
  /// Block row of the ghost of each local vertex: the copy of x_i that the part across the cut uses.
  std::array<int, 4> enriched_row{};
  /// The ghost's offset (CutPiece::offset_m) in the part that uses it: zero for a ghost this tet
  /// created (it starts as a copy of the vertex it splits from); for a tet that joined a ghost that
  /// had moved already (a tet completed at a later step of the same stroke), c_g minus where the
  /// part had the vertex, so the part starts as the tet was and the join adds no energy; from then on
  /// it moves with the shared ghost (a seam the size of the offset stays).
  TetPositions enrichment_offset_m{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                                   Eigen::Vector3d::Zero()};
  /// The weight of a part (w_a or w_b).
  [[nodiscard]] double weight(CutPart part) const { return part == CutPart::above ? weight_above : weight_below; }
  /// Psi of local vertex i in part p: 0 where the part uses the real vertex, +-1 where its ghost.
  [[nodiscard]] double shift(int i, CutPart part) const {
    return enrichment_shift(cut.side[static_cast<size_t>(i)], part);
  }
};

/// CutPiece::ghost_row of a held copy (issue 41): a copy of a fixed vertex whose pieces touch held
/// material (a tet whose four vertices are fixed) stays at the vertex's rest position and has no
/// unknowns. Held copy h (DeformableBody::held_copies()) is HELD_COPY_FIRST + h: negative, so the
/// dynamics treats it as the fixed vertex itself; the drawn surface tells it from the real vertex.
inline constexpr int HELD_COPY_FIRST = std::numeric_limits<int>::min();
[[nodiscard]] constexpr bool is_held_copy(int ghost_row) { return ghost_row < HELD_COPY_FIRST + (1 << 30); }
[[nodiscard]] constexpr int held_copy_index(int ghost_row) { return ghost_row - HELD_COPY_FIRST; }

/// A piece of a cut tet as an element copy: its rest volume fraction and, per local vertex, the
/// row of its ghost there (-1: the real vertex; is_held_copy(): a held copy) and the ghost's offset:
/// p_j = X_j + c_{row_j} - offset_j, so that a piece joining a ghost that has moved starts where its
/// material was.
struct CutPiece {
  double weight = 0.0;
  std::array<int, 4> ghost_row{-1, -1, -1, -1};
  TetPositions offset_m{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(),
                        Eigen::Vector3d::Zero()};
};

/// The two pieces of a single cut (above, below) from its CutTet.
std::array<CutPiece, 2> pieces_of(const CutTet& cut_tet);

/// Slots of the blocks of a cut tet over its local DOFs (XfemElasticity::dof_count): index D I + J
/// for D DOFs; DOF I < 4 is u of local vertex I, I >= 4 the ghost row ghost_rows(k)[I - 4]. -1
/// where there is no block: the u of a fixed vertex, and two DOFs no piece uses together (for a
/// single cut: the a-a blocks of two vertices on opposite sides, eq. 4.6).
using CutTetSlots = std::span<int>;

/// Positions of the 4 vertices of `piece`: x_j, or X_j + c_g - offset_j for a ghost, from the real
/// positions x and rest positions X of the tet's local vertices and the unknowns (the ghosts' c are
/// read from their rows). [m]
TetPositions piece_positions(const CutPiece& piece, const TetPositions& real_positions_m,
                             const TetPositions& rest_positions_m, const Eigen::VectorXd& displacement_m);

/// A co-rotational piece strained further than this (|sym(R^T F) - I|, Frobenius norm) gets in its
/// tangent the twist stiffness R K R^T lacks, where positive (a stretched piece resists turning).
/// Pieces pulled that far by their ghosts (the chips of 30 + 30 hatched strokes, sheared 1.78x and
/// 0.55x) otherwise turned past the Newton corrections' trigger in every step; no piece of the shipped
/// cutting scenarios is strained that far (their steps unchanged); for every piece the term cost the
/// frog's plain steps 12-22% for no correction saved in cut_frog_complete (docs/BENCHMARKS.md).
inline constexpr double TWIST_STIFFNESS_STRAIN = 0.25;

class XfemElasticity {
 public:
  /// `rotation`: when the parts' rotation extraction stops (validated by the caller's body settings).
  /// `elements`: the body's material model and constants per material, as
  /// CorotationalElasticity::elements(); a cut tet's TetRest::material picks one.
  XfemElasticity(ElementModel elements, const RotationSettings& rotation)
      : m_elements(std::move(elements)), m_rotation_settings(rotation) {}
  /// Co-rotational linear with these Lame parameters per material.
  XfemElasticity(std::vector<LameParameters> lame, const RotationSettings& rotation)
      : XfemElasticity(ElementModel(MaterialModel::corotational_linear, std::move(lame)), rotation) {}

  /// Room for this many cut tets without reallocation.
  void reserve(int cut_tets);

  /// How many assembly lists a phase has: the parts a step's team runs side by side.
  static constexpr int LIST_PARTS = MAX_STEP_THREADS;
  /// The cut tets are assembled in their mesh tets' lists of the uncut assembly
  /// (CorotationalElasticity::assembly_list_of_tets): `list_of_tet[t]` for mesh tet t, lists
  /// LIST_PARTS ph + part for phase ph < `phases`, whose parts share no vertex, then list LIST_PARTS
  /// phases alone. Two cut tets in one phase's parts then share no row (a piece's ghosts copy its
  /// tet's vertices) and no block, and a step's team assembles them side by side (issue 41: 80% of a
  /// hatched frog's assembly was its cut tets', on one thread). Until it is set, one list. Throws
  /// std::invalid_argument (nothing changed) for a negative phase count, a list out of range, or
  /// fewer entries than a cut tet's tet needs.
  void set_assembly_lists(std::vector<int> list_of_tet, int phases);

  /// Adds a cut tet with its rest data. Both parts' rotations start from `rotation` (the tet's
  /// rotation before the cut: with each ghost a copy of its vertex both parts coincide with the tet). Slots start at -1 (set
  /// them with slots() before the first evaluate with a tangent).
  void add(const CutTet& cut_tet, const TetRest& rest, const Eigen::Matrix3d& rotation);
  /// The same for a tet cut into any number of pieces (>= 2; `cut_tet` keeps its vertices and its
  /// first cut, its two-part fields are not used), piece p's rotation starting from rotations[p].
  /// Throws std::invalid_argument for fewer than two pieces, weights that are not positive or do not
  /// add up to 1 (to 1e-12), a ghost sign other than +-1, or a rotation per piece missing.
  void add(const CutTet& cut_tet, std::span<const CutPiece> pieces, const TetRest& rest,
           std::span<const Eigen::Matrix3d> rotations);
  /// Cut tet k no longer counts (a later cut replaced it by a new cut tet of more pieces); its blocks
  /// and slots stay, its forces are no longer added.
  void retire(int k) { m_retired[static_cast<std::size_t>(k)] = 1; }
  [[nodiscard]] bool retired(int k) const { return m_retired[static_cast<std::size_t>(k)] != 0; }
  /// Piece p of cut tet k no longer counts: its part was taken out of the dynamics
  /// (DeformableBody::park_parts_outside). Its forces, blocks and energy are no longer added.
  void park(int k, int p) { m_parked[piece_begin(k) + static_cast<std::size_t>(p)] = 1; }
  [[nodiscard]] bool parked(int k, int p) const { return m_parked[piece_begin(k) + static_cast<std::size_t>(p)] != 0; }
  /// Whether every piece of cut tet k is parked (then it adds nothing, as a retired one).
  [[nodiscard]] bool all_parked(int k) const;

  [[nodiscard]] int cut_tet_count() const { return static_cast<int>(m_cut_tets.size()); }
  [[nodiscard]] const std::vector<CutTet>& cut_tets() const { return m_cut_tets; }
  [[nodiscard]] const TetRest& rest(int k) const { return m_rest[static_cast<size_t>(k)]; }
  /// Piece `piece` of cut tet k (a single cut: 0 above, 1 below).
  [[nodiscard]] const CutPiece& piece(int k, int piece) const { return m_pieces[piece_begin(k) + static_cast<std::size_t>(piece)]; }
  [[nodiscard]] std::size_t piece_count(int k) const { return piece_begin(k + 1) - piece_begin(k); }
  /// The distinct ghost rows of cut tet k, in first use order: its local DOFs 4, 5, ...
  [[nodiscard]] std::span<const int> ghost_rows(int k) const {
    const auto begin = static_cast<std::size_t>(m_ghost_begin[static_cast<std::size_t>(k)]);
    const auto end = static_cast<std::size_t>(m_ghost_begin[static_cast<std::size_t>(k) + 1]);
    return std::span<const int>(m_ghost_rows).subspan(begin, end - begin);
  }
  /// 4 + ghost_rows(k).size().
  [[nodiscard]] int dof_count(int k) const { return 4 + static_cast<int>(ghost_rows(k).size()); }
  /// The local DOF pairs of cut tet k whose block exists: coupled[dof_count(k) i + j] = 1 when some
  /// piece of it that is not parked uses both i and j (its four DOFs, piece_dofs); the four u DOFs
  /// always couple. One pass over the pieces (asking pair by pair cost 5% of a hatched run).
  void coupled_dofs(int k, std::vector<std::uint8_t>& coupled) const;
  /// Marks keep[slot] for every slot of cut tet k's table whose DOFs couple (coupled_dofs): the
  /// blocks its unparked pieces write (evaluate's), and its u-u blocks.
  void mark_written_slots(int k, std::vector<std::uint8_t>& keep) const;
  [[nodiscard]] CutTetSlots slots(int k) {
    const auto begin = m_slot_begin[static_cast<std::size_t>(k)];
    return std::span<int>(m_slots).subspan(begin, m_slot_begin[static_cast<std::size_t>(k) + 1] - begin);
  }
  /// R_p of cut tet k at the last evaluate() (a single cut: piece 0 above, 1 below).
  [[nodiscard]] const Eigen::Matrix3d& rotation(int k, CutPart part) const {
    return m_rotations[piece_begin(k) + (part == CutPart::above ? 0 : 1)];
  }
  /// R_p of piece p of cut tet k at the last evaluate().
  [[nodiscard]] const Eigen::Matrix3d& rotation(int k, int piece) const {
    return m_rotations[piece_begin(k) + static_cast<std::size_t>(piece)];
  }

  /// One pass over the cut tets. `positions_m`: real positions of all vertices (3 per vertex);
  /// `displacement_m`: the unknowns (the ghosts' c are read from their rows). Adds the forces on the
  /// real vertices into `vertex_forces_n` (3 per vertex), those on the ghosts into their rows of
  /// `internal_force_n` (3 per unknown) and, when `tangent` is given, the blocks through the slots.
  /// With `elastic_energy_j`, also their elastic energy with the rotations just extracted
  /// (elastic_energy_j() there, to round-off). [J]
  /// `into` ahead: the pieces' rotations go beside their own (ExtractInto), which stay as they were.
  /// With `team` (of LIST_PARTS members) each phase's lists run side by side, each writing only its
  /// own entries, the energies added list by list in order: bitwise the same result as without.
  void evaluate(const Eigen::VectorXd& positions_m, const Eigen::VectorXd& displacement_m,
                Eigen::VectorXd& vertex_forces_n, Eigen::VectorXd& internal_force_n, BlockSparseMatrix* tangent,
                double* elastic_energy_j = nullptr, ExtractInto into = ExtractInto::own, WorkTeam* team = nullptr);
  /// The rotations and warm starts of the last evaluate() ahead become the pieces' own, the own ones
  /// the turns before.
  void take_ahead() {
    m_rotations.swap(m_rotations_ahead);
    m_turns_before.swap(m_warm_starts);
    m_warm_starts.swap(m_warm_starts_ahead);
  }

  /// Sum over the cut tets of w_a E(part a) + w_b E(part b), with the rotations of these
  /// positions (warm starts unchanged). [J]
  /// Added list by list as evaluate() adds them (side by side with a team).
  [[nodiscard]] double elastic_energy_j(const Eigen::VectorXd& positions_m, const Eigen::VectorXd& displacement_m,
                                        WorkTeam* team = nullptr) const;

  /// Forgets the warm starts (rotations back to identity).
  void reset_rotations();
  /// The pieces' rotations, warm starts and turns before (as CorotationalElasticity's: each
  /// extraction starts from extrapolated_turn(warm start, turn before)), cut tet after cut tet
  /// (retired ones included).
  [[nodiscard]] const std::vector<Eigen::Matrix3d>& piece_rotations() const { return m_rotations; }
  [[nodiscard]] const std::vector<Eigen::Quaterniond>& piece_warm_starts() const { return m_warm_starts; }
  [[nodiscard]] const std::vector<Eigen::Quaterniond>& piece_turns_before() const { return m_turns_before; }
  /// Sets the three; throws std::invalid_argument (nothing changed) unless there is one of each per piece.
  void restore_rotations(const std::vector<Eigen::Matrix3d>& rotations,
                         const std::vector<Eigen::Quaterniond>& warm_starts,
                         const std::vector<Eigen::Quaterniond>& turns_before);

 private:
  // Real positions of the local vertices of cut tet k.
  void gather(size_t k, const Eigen::VectorXd& positions_m, TetPositions& real_m) const;
  // Piece p's local DOF at each of its tet's vertices: u of the vertex (0-3) or its ghost (>= 4).
  [[nodiscard]] std::array<int, 4> piece_dofs(std::size_t p) const;
  // Each counted piece of `cut_tets` with its F and rotation, four at a time in SIMD lanes: for
  // evaluate() (into the pieces' own or ahead set) and the energy (from copies). Defined in the .cpp.
  template <class Visit>
  void in_piece_rotation_batches(const std::vector<int>& cut_tets, const Eigen::VectorXd& positions_m,
                                 const Eigen::VectorXd& displacement_m, std::vector<Eigen::Quaterniond>* warm_starts,
                                 std::vector<Eigen::Matrix3d>* rotations, std::vector<Eigen::Quaterniond>* turns_before,
                                 bool keep, Visit visit) const;
  // evaluate's first pass: every counted piece's F (into m_gradients) and its rotation into
  // `rotations` from extrapolated_turn(warm start, turn before); `keep`: the own set's, which keeps
  // the warm starts it replaces as the turns before.
  void extract_piece_rotations(const std::vector<int>& cut_tets, const Eigen::VectorXd& positions_m,
                               const Eigen::VectorXd& displacement_m, std::vector<Eigen::Matrix3d>& rotations,
                               std::vector<Eigen::Quaterniond>& warm_starts, bool keep);
  // What evaluate() hands each list.
  struct Pass {
    const Eigen::VectorXd& positions_m;
    const Eigen::VectorXd& displacement_m;
    Eigen::VectorXd& vertex_forces_n;
    Eigen::VectorXd& internal_force_n;
    BlockSparseMatrix* tangent;
    std::vector<Eigen::Matrix3d>& rotations;
    std::vector<Eigen::Quaterniond>& warm_starts;
    bool keep;         // the own set (ExtractInto::own)
    bool with_energy;  // sum the pieces' energies
  };
  // evaluate() of the cut tets `cut_tets` (counted ones only), in order; their energy (0 without).
  double evaluate_list(const std::vector<int>& cut_tets, const Pass& pass);
  // The energy of the counted cut tets `cut_tets`, added in order.
  [[nodiscard]] double energy_of(const std::vector<int>& cut_tets, const Eigen::VectorXd& positions_m,
                                 const Eigen::VectorXd& displacement_m) const;
  // job(list) for every list, each phase's parts side by side with `team`, then the last list; the
  // sum of what the jobs return, added list by list in order (the same with a team or without).
  template <class Job>
  double sum_over_lists(WorkTeam* team, Job&& job) const;
  // The list cut tet k is assembled in.
  [[nodiscard]] int list_of(const CutTet& cut_tet) const;

  [[nodiscard]] std::size_t piece_begin(int k) const {
    return static_cast<std::size_t>(m_piece_begin[static_cast<std::size_t>(k)]);
  }

  // Flat, cut tet after cut tet (one pass over contiguous memory): per cut tet, per piece, ghost
  // rows and slots with their begin offsets.
  ElementModel m_elements;  // the model, constants per material
  RotationSettings m_rotation_settings;
  std::vector<CutTet> m_cut_tets;
  std::vector<TetRest> m_rest;
  std::vector<std::uint8_t> m_retired;  // per cut tet
  std::vector<std::uint8_t> m_parked;   // per piece
  std::vector<int> m_piece_begin{0};
  std::vector<CutPiece> m_pieces;
  std::vector<std::array<int, 4>> m_ghost_dofs;  // per piece and local vertex: its local DOF, -1 real
  std::vector<Eigen::Matrix3d> m_rotations;       // per piece (a single cut: above, below)
  std::vector<Eigen::Quaterniond> m_warm_starts;  // per piece
  std::vector<Eigen::Matrix3d> m_rotations_ahead;  // an evaluation ahead's: all pieces', the ones it skips copied
  std::vector<Eigen::Quaterniond> m_warm_starts_ahead;
  std::vector<Eigen::Quaterniond> m_turns_before;  // per piece: its warm start before the last own extraction
  std::vector<Eigen::Matrix3d> m_gradients;  // per piece: its F at the last evaluate (evaluate's working array)
  std::vector<int> m_ghost_begin{0};
  std::vector<int> m_ghost_rows;
  std::vector<std::size_t> m_slot_begin{0};
  std::vector<int> m_slots;
  std::vector<int> m_list_of_tet;  // per mesh tet (set_assembly_lists); empty: every cut tet in list 0
  // LIST_PARTS lists per phase, then the one run alone: cut tets, increasing.
  std::vector<std::vector<int>> m_lists = std::vector<std::vector<int>>(1);
};

}  // namespace tissue
