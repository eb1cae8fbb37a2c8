// Co-rotational linear elasticity of a whole tet mesh (Mueller et al.; dissertation eq. 3.13):
// per-tet rotations, internal forces f_e = R K_e (R^T x - X) and the tangent R K_e R^T,
// assembled into a BlockSparseMatrix through precomputed slots.
#pragma once

#include "core/material/material.hpp"
#include "core/fem/element_model.hpp"
#include "core/fem/rotation.hpp"
#include "core/fem/tet_element.hpp"
#include "core/mesh/tet_mesh.hpp"
#include "core/system/assembly.hpp"
#include "core/system/block_sparse_matrix.hpp"
#include "core/system/work_team.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <span>
#include <vector>

namespace tissue {

class CorotationalElasticity {
 public:
  /// Precomputes shape gradients and volumes. `materials`: one per region of the mesh
  /// (TetMesh::region_count(), see resolve_region_materials), each tet taking its region's. Throws
  /// ParameterError for an invalid material, a count that does not match, or an invalid rotation
  /// setting.
  /// `vertex_order` (a permutation of the vertices, such as locality_order(), or empty for vertex
  /// order): each assembly part visits its tets by the earliest of their vertices in it, so that
  /// consecutive tets write nearby blocks when the system's rows are numbered in the same order.
  /// `model`: how every tet answers (co-rotational linear, or stable Neo-Hookean: then the rotations
  /// are still extracted, for the protections and the elementLocal contact stiffness).
  CorotationalElasticity(const TetMesh& mesh, const std::vector<Material>& materials,
                         const RotationSettings& rotation = {}, const std::vector<int>& vertex_order = {},
                         MaterialModel model = MaterialModel::corotational_linear);
  /// One material for the whole mesh (every region).
  CorotationalElasticity(const TetMesh& mesh, const Material& material, const RotationSettings& rotation = {},
                         const std::vector<int>& vertex_order = {})
      : CorotationalElasticity(mesh, std::vector<Material>(static_cast<size_t>(mesh.region_count()), material),
                               rotation, vertex_order) {}

  [[nodiscard]] int tet_count() const { return static_cast<int>(m_tets.size()); }
  /// The Lame parameters of each material (TetRest::material indexes them).
  [[nodiscard]] const std::vector<LameParameters>& lame() const { return m_elements.lame; }
  [[nodiscard]] const LameParameters& lame_of(const TetRest& rest) const { return m_elements.lame_of(rest); }
  /// The material model and its per-material constants (shared with the XFEM pieces).
  [[nodiscard]] const ElementModel& elements() const { return m_elements; }
  [[nodiscard]] const TetRest& rest(int tet) const { return m_rest[stored(tet)]; }
  [[nodiscard]] const Eigen::Matrix3d& rotation(int tet) const { return m_rotations[stored(tet)]; }
  /// The same turn as a unit quaternion (the next extraction starts from it extrapolated).
  [[nodiscard]] const Eigen::Quaterniond& turn(int tet) const { return m_warm_starts[stored(tet)]; }

  /// Hands `tet` over to another model (a cut tet, modelled by XfemElasticity): evaluate() and
  /// elastic_energy_j() skip it from now on. Throws ParameterError for an id out of range.
  void exclude(int tet);
  [[nodiscard]] bool is_excluded(int tet) const { return m_excluded[stored(tet)] != 0; }
  /// visit(vertices, rest, rotation) for the tets not excluded at storage indices [first, end)
  /// (tet_id()), in storage order: a pass that streams the per-tet data as a step does.
  template <class Visit>
  void for_each_included(size_t first, size_t end, Visit&& visit) const {
    for (size_t k = first; k < end; ++k) {
      if (m_excluded[k] == 0) visit(m_tets[k], m_rest[k], m_rotations[k]);
    }
  }

  /// One pass over the (not excluded) tets at the current positions (3 per vertex, [m]):
  /// updates each R_e (warm-started from the last step), adds the internal force f_int
  /// (the restoring force in M a + D v + f_int = f_ext, [N], 3 per vertex) into `internal_forces_n`,
  /// and, when `tangent` is given, adds R_e K_e R_e^T into it through `slots` (blocks whose slot is -1,
  /// i.e. that touch a fixed vertex, are skipped). The caller zeroes both outputs.
  ///
  /// The tets go in a fixed order of phases: the two halves of the mesh (split at the median along
  /// its longest axis) without the tets that share a vertex with the other half; then the two halves
  /// of those (the separator, split the same way), and once more; then what separates these. With a team
  /// of two the halves of a phase run side by side: they write disjoint entries, and every entry
  /// receives its terms in the same order as with one thread, so the result is bitwise the same.
  /// With `elastic_energy_j`, also the elastic energy at these positions with the rotations just
  /// extracted (elastic_energy_j() there, bitwise: both add the terms in assembly order). [J]
  /// `into` ahead: the rotations go beside the tets' own (ExtractInto), which stay as they were.
  void evaluate(const Eigen::VectorXd& positions_m, Eigen::VectorXd& internal_forces_n, BlockSparseMatrix* tangent,
                const std::vector<TetSlots>* slots, WorkTeam* team = nullptr, double* elastic_energy_j = nullptr,
                ExtractInto into = ExtractInto::own);
  /// The rotations and warm starts of the last evaluate() ahead become the tets' own, the own ones
  /// the turns before (an excluded tet's are the same in all sets).
  void take_ahead() {
    m_rotations.swap(m_rotations_ahead);
    m_turns_before.swap(m_warm_starts);
    m_warm_starts.swap(m_warm_starts_ahead);
  }

  /// How many parts the assembly runs side by side (a team's members beyond this wait).
  static constexpr int ASSEMBLY_PARTS = MAX_STEP_THREADS;
  /// One phase of the assembly: parts that share no vertex. The lists hold storage indices (see
  /// tet_id()): the per-tet data is stored in the order the assembly visits it, phase by phase and
  /// part by part, each part by the earliest of its tets' vertices in the vertex order, so that a
  /// step streams it.
  using AssemblyPhase = std::array<std::vector<int>, ASSEMBLY_PARTS>;
  [[nodiscard]] const std::vector<AssemblyPhase>& assembly_phases() const { return m_phases; }
  /// The tets assembled alone, after the phases (storage indices).
  [[nodiscard]] const std::vector<int>& serial_tets() const { return m_serial_tets; }
  /// Per mesh tet, its assembly list: ASSEMBLY_PARTS ph + part for the part of phase ph it is in, or
  /// ASSEMBLY_PARTS assembly_phases().size() for a serial tet (XfemElasticity::set_assembly_lists).
  [[nodiscard]] std::vector<int> assembly_list_of_tets() const;
  /// The mesh's id of the tet at storage index k.
  [[nodiscard]] int tet_id(int k) const { return m_tet_id[static_cast<size_t>(k)]; }

  /// Elastic energy sum_e V_e (mu eps:eps + lambda/2 tr(eps)^2), eps = sym(R_e^T F_e) - I, with the
  /// rotations of these positions (the stored warm starts are not changed). [J]
  /// The terms added as evaluate() adds them (each assembly phase's parts side by side with a team
  /// of two, part by part, then the serial tets): bitwise evaluate()'s energy from the same warm
  /// starts, with one thread or two.
  [[nodiscard]] double elastic_energy_j(const Eigen::VectorXd& positions_m, WorkTeam* team = nullptr) const;

  /// Forgets the warm starts (rotations back to identity, no turn), e.g. after a state was restored.
  void reset_rotations();
  /// The rotations, their warm starts and the turns before them (each extraction starts from
  /// extrapolated_turn(warm start, turn before); an evaluation's own extraction makes the warm start
  /// the turn before), per tet in mesh order: what a saved state must carry to continue bitwise.
  [[nodiscard]] std::vector<Eigen::Matrix3d> rotations() const;
  [[nodiscard]] std::vector<Eigen::Quaterniond> warm_starts() const;
  [[nodiscard]] std::vector<Eigen::Quaterniond> turns_before() const;
  /// Sets the three; throws std::invalid_argument (nothing changed) unless there is one of each per tet.
  void restore_rotations(const std::vector<Eigen::Matrix3d>& rotations,
                         const std::vector<Eigen::Quaterniond>& warm_starts,
                         const std::vector<Eigen::Quaterniond>& turns_before);

 private:
  /// Adds the force of the tet at storage index k and (with `tangent`) its blocks, with F = f and
  /// the rotation r just extracted (the own set's or the ahead one's).
  void add_tet(size_t k, const Eigen::Matrix3d& f, const Eigen::Matrix3d& r, Eigen::VectorXd& internal_forces_n,
               BlockSparseMatrix* tangent, const std::vector<TetSlots>* slots) const;

  /// visit(t, F, R) for the tets tet_at(0) .. tet_at(count - 1) that are not excluded, in order, their
  /// rotations extracted ROTATION_BATCH at a time side by side (SIMD lanes). A step's (`warm_starts`,
  /// `rotations` and `turns_before` given: the own set, or the ahead one, its warm starts copied from
  /// the own first) from extrapolated_turn(own warm start, turn before), an own one keeping its warm
  /// starts as the turns before; else from copies of the warm starts as they are, the rotations kept
  /// in the batch (reporting must not change the dynamics, and a report at the positions of the last
  /// evaluation starts where it ended). Defined in the .cpp, for the hot kernels there.
  /// The energy of the tets `tets` (storage indices) at the positions, added in their order.
  [[nodiscard]] double energy_of(const std::vector<int>& tets, const Eigen::VectorXd& positions_m) const;

  template <class TetAt, class Visit>
  void in_rotation_batches(size_t count, TetAt tet_at, const Eigen::VectorXd& positions_m,
                           std::vector<Eigen::Quaterniond>* warm_starts, std::vector<Eigen::Matrix3d>* rotations,
                           std::vector<Eigen::Quaterniond>* turns_before, Visit visit) const;

  /// Adds the forces and blocks of `tets` (skipping excluded ones), rotations in batches, and their
  /// energy into `energy_j` when given.
  void add_tets(const std::vector<int>& tets, const Eigen::VectorXd& positions_m, Eigen::VectorXd& internal_forces_n,
                BlockSparseMatrix* tangent, const std::vector<TetSlots>* slots, double* energy_j, ExtractInto into);

  /// Splits the tets into the parts and the separator (see evaluate()).
  /// Then stores the per-tet data in assembly order (m_tet_id, m_storage).
  void partition(const TetMesh& mesh, const std::vector<int>& vertex_order);
  /// Sorts each list by the vertex order (see assembly_phases()).
  void sort_lists(const TetMesh& mesh, const std::vector<int>& vertex_order);
  [[nodiscard]] size_t stored(int tet) const { return static_cast<size_t>(m_storage[static_cast<size_t>(tet)]); }

  // Per tet, by storage index (the assembly's order):
  std::vector<int> m_tet_id;   // the mesh's id
  std::vector<int> m_storage;  // per mesh id: the storage index
  std::vector<Tet> m_tets;
  std::vector<AssemblyPhase> m_phases;
  std::vector<int> m_serial_tets;
  std::vector<TetRest> m_rest;
  std::vector<Eigen::Matrix3d> m_rotations;
  std::vector<Eigen::Quaterniond> m_warm_starts;
  std::vector<Eigen::Matrix3d> m_rotations_ahead;  // an evaluation ahead's (ExtractInto)
  std::vector<Eigen::Quaterniond> m_warm_starts_ahead;
  std::vector<Eigen::Quaterniond> m_turns_before;  // the own warm starts before their last extraction
  std::vector<char> m_excluded;  // 1 = modelled elsewhere (cut)
  ElementModel m_elements;  // the model, Lame parameters per material
  RotationSettings m_rotation_settings;
};

/// Lumped per vertex as the mass is (eq. 4.15): each tet gives V / 4 times its region's
/// `per_region_per_m3` to each of its vertices. One per vertex. Throws std::invalid_argument for fewer
/// values than the mesh has regions.
std::vector<double> lumped_vertex_sums(const TetMesh& mesh, std::span<const double> per_region_per_m3);

/// Lumped mass: lumped_vertex_sums of each region's density (`materials` as for
/// CorotationalElasticity). [kg], one per vertex.
std::vector<double> lumped_vertex_masses(const TetMesh& mesh, const std::vector<Material>& materials);

}  // namespace tissue
