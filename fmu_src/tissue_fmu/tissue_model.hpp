// The Tissue FMU's model behind the FMI layer (fmi3/model.hpp): the core's Tissue built from the
// parameters in the layer's ValueStore, stepped by doStep, its outputs (contact, surface mesh
// arrays, counters, energies) and its states. Range checks are the core's own validate()s.
#pragma once

#include "core/mesh/tet_mesh.hpp"
#include "core/tissue.hpp"
#include "fmi3/model.hpp"
#include "ports/surface_binary.hpp"
#include "core/system/background_work.hpp"
#include "tissue_fmu/variables.hpp"

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace tissue::tissue_fmu {

/// The tissue's settings as the store holds them (core/tissue_settings_schema.hpp), each checked.
TissueParameters tissue_parameters(const fmi3::ValueStore& values);
/// The core's settings from the FMU's parameters; fixed vertices only if `mesh` is given. Throws
/// ParameterError for values the core refuses.
TissueSettings tissue_settings(const fmi3::ValueStore& values, const TetMesh* mesh);
/// The tool pose from the tool inputs, as set (the core checks and normalizes it, Tissue::set_tool).
ToolPose tool_pose(const fmi3::ValueStore& values);
/// The core's Tissue the FMU's parameters describe: the mesh ("frog", the embedded one, or a file),
/// the settings and the render surface, relative paths taken from `resource_path`. The FMU builds
/// its tissue with it, the Python module a scenario's. Throws VariableError naming the parameter
/// (a mesh or surface that cannot be loaded), ParameterError for values the core refuses.
std::unique_ptr<Tissue> make_tissue(const fmi3::ValueStore& values, const std::string& resource_path);
/// The same from parameters already read (tissue_parameters()).
std::unique_ptr<Tissue> make_tissue(const TissueParameters& parameters, const std::string& resource_path);

class TissueModel final : public fmi3::Model {
 public:
  TissueModel(const fmi3::ModelContext& context, const fmi3::ValueStore& values);

  void validate_parameters(const fmi3::ValueStore& values) const override;
  void parameters_changed() override {
    settle();
    m_dirty = true;
  }
  void enter_initialization_mode(double start_time_s) override;
  void exit_initialization_mode() override;
  fmi3::StepOutcome do_step(double current_time_s, double step_s) override;
  void reset() override;

  void get_float64(const fmi3::VariableInfo& info, std::span<double> values) override;
  void get_uint32(const fmi3::VariableInfo& info, std::span<std::uint32_t> values) override;
  void get_uint64(const fmi3::VariableInfo& info, std::span<std::uint64_t> values) override;
  void get_boolean(const fmi3::VariableInfo& info, std::span<bool> values) override;
  std::span<const std::uint8_t> get_binary(const fmi3::VariableInfo& info) override;

  [[nodiscard]] std::unique_ptr<fmi3::ModelState> save() const override;
  void restore(const fmi3::ModelState& state) override;
  void serialize(const fmi3::ModelState& state, serial::ByteWriter& writer) const override;
  [[nodiscard]] std::unique_ptr<fmi3::ModelState> deserialize(serial::ByteReader& reader) const override;

  /// The core, once built; for tests and benchmarks of the layer.
  [[nodiscard]] Tissue* tissue() { return m_tissue.get(); }

 private:
  void build();
  /// With a render surface: room for its outputs' arrays and bytes as large as the room it holds
  /// for a session's cuts, written now (CutRenderSurface::point_room), not at the first cut.
  void reserve_render_outputs();
  void ensure_built();
  /// surface.revision for the current state. A step only marks it stale: the first read after it
  /// (an output, the surface's bytes, a saved state, a prepared frame) compares the drawn surface's
  /// counts with the last ones, so a step between frames makes no tet-skin lists (DESIGN, "Drawn when
  /// read"). No surface work may be running when it is stale (prepare_surface brings it up to date
  /// before it starts one).
  std::uint64_t surface_revision() const;
  /// surface.revision is `revision` for the tissue as it is now (built or restored): what later reads
  /// compare with are its drawn surface's counts now, and the drawn mesh is made again when read.
  void start_surface_revision(std::uint64_t revision);
  /// Steps moved (and may have cut) the tissue: the drawn mesh and surface.revision are made again
  /// when next read.
  void surface_moved();
  /// What surface.revision follows besides the cut tets: the tet skin's triangle count (a join that
  /// let go changes it); none for a render surface, which changes only with the cuts (so that a step
  /// does not make the tet skin's lists for a surface it does not draw).
  [[nodiscard]] std::size_t revision_triangles() const;
  /// Logs once that the surface outgrew the arrays' capacities (on reading the arrays or their counts).
  void warn_if_arrays_truncate();
  /// The drawn surface (the render surface when surface.renderSurface names one, else the tet skin),
  /// brought up to date on the first read after a build, a step or a restore.
  const ports::SurfaceMesh& drawn_mesh();
  void drawn_embedding(ports::SurfaceEmbedding& embedding);
  void drawn_nodes(ports::SurfaceNodes& nodes);
  /// Whether m_embedding_bytes hold the current revision's surface.embedding for this output switch.
  [[nodiscard]] bool embedding_encoded(bool mesh_output) const;
  /// surface.embedding's bytes for the current revision (encoded once per revision and output switch).
  const std::vector<std::uint8_t>& embedding_bytes(bool mesh_output);
  /// After a step: when surface.prepareAfterStep is set and the revision changed, embedding_bytes()
  /// in the background (m_surface_work).
  void prepare_surface();
  /// Waits for the background preparation; every call that reads or changes the tissue beyond the
  /// contact outputs and the counters calls this first.
  void settle() const { m_surface_work.wait(); }

  fmi3::ModelContext m_context;
  const fmi3::ValueStore& m_values;
  double m_start_time_s = 0.0;
  bool m_dirty = true;  // a parameter changed since the Tissue was built
  std::unique_ptr<Tissue> m_tissue;
  // surface.revision and what it was last compared with; brought up to date by surface_revision().
  mutable std::uint64_t m_surface_revision = 0;
  mutable bool m_surface_revision_stale = false;
  std::uint64_t m_integrator_iterations = 0;  ///< integrator.iterations
  mutable std::uint64_t m_surface_triangles = 0;  // at the last revision check
  mutable std::size_t m_surface_cut_tets = 0;     // at the last revision check
  ports::SurfaceMesh m_drawn;
  bool m_drawn_current = false;
  ports::SurfaceEmbedding m_embedding;     // scratch of get_binary
  ports::SurfaceNodes m_nodes;             // scratch of get_binary
  std::vector<std::uint8_t> m_mesh_bytes, m_embedding_bytes, m_nodes_bytes;
  // What m_embedding_bytes hold: the surface of this revision, with the output switch so (none: stale).
  struct EncodedEmbedding {
    std::uint64_t revision = 0;
    bool mesh_output = false;
  };
  std::optional<EncodedEmbedding> m_encoded_embedding;
  bool m_capacity_warned = false;
  // cut.bladeDepth at the last doStep's end, found before its surface job starts, so that a read
  // beside the job (tissue-host's, after every step) touches nothing the job reads or writes (none:
  // found when read, after a restore, a reset or a failed step).
  std::optional<double> m_blade_depth_m;
  // Last: destroyed first, so that a job still running ends before the members it uses.
  mutable BackgroundWork m_surface_work;
};

}  // namespace tissue::tissue_fmu
