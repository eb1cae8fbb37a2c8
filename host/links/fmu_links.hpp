// The host's two FMU instances as the session uses them: the Tissue FMU (tool pose in; the tissue
// sample, counters and surface out) and the HapticLoop FMU (device and tissue sample in; tool pose
// and device force out), and the relay of the tissue sample between them (sample_relay.hpp). Value
// references are looked up once by name; the calls of a step or a tick are the importer's thin calls
// on preallocated buffers (no allocation, no exception). Scenario parameters are applied by name,
// converted to each variable's type, and refused with the key.
#pragma once

#include "device/device.hpp"
#include "importer/fmu3.hpp"
#include "importer/fmu3_instance.hpp"
#include "links/recycled_bytes.hpp"
#include "links/sample_relay.hpp"
#include "output/surface_frame.hpp"
#include "scenario/scenario.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tissue::host {

/// Haptic side -> dynamics side: the tool the tissue steps with.
struct ToolCommand {
  double time_s = 0.0;
  std::array<double, 3> position_m{};
  std::array<double, 4> orientation_wxyz{1.0, 0.0, 0.0, 0.0};
  std::int64_t mode = 0;
};

/// What the haptic loop outputs after a tick.
struct HapticOutputs {
  ToolCommand tool;
  std::array<double, 3> device_force_n{};
  double observed_energy_j = 0.0, dissipated_energy_j = 0.0;
  bool clamped = false, rate_limited = false, passivity_acted = false;
};

/// Applies scenario parameters by name; throws ScenarioError naming `where`.name for a variable
/// the FMU does not have, a value of the wrong kind, or a value the FMU refuses (with its log).
void apply_parameters(Fmu3Instance& instance, const std::vector<ParameterSetting>& parameters,
                      const std::string& where);

/// Completes frames captured without their mapping (SurfaceFrame::embedding_bytes): decodes the
/// embedding (once per bytes: kept while the next frames share them) and maps the nodes to the
/// points. One object per consumer thread. Throws FmuError for bytes that do not decode or nodes
/// that are not the embedding's.
class SurfaceMapping {
 public:
  void complete(SurfaceFrame& frame);

 private:
  std::shared_ptr<const std::vector<std::uint8_t>> m_bytes;  // what m_embedding was decoded from
  std::shared_ptr<const ports::SurfaceEmbedding> m_embedding;
  ports::SurfaceNodes m_nodes;
};

class TissueLink {
 public:
  /// Instantiates, applies the parameters, initializes at t = 0. Throws ScenarioError / FmuError.
  TissueLink(const Fmu3& fmu, const std::vector<ParameterSetting>& parameters);

  void set_tool(const ToolCommand& tool);
  /// Sets surface.prepareAfterStep for the next steps: whether a step that cuts has the FMU prepare
  /// surface.embedding after it, in its own thread (set when a frame will be read in the next slot).
  /// Only calls the FMU when the value changes; nothing for an FMU without the input.
  void prepare_surface_after_step(bool prepare);
  DoStepResult step(double time_s, double step_s);
  /// The cut counters into `sample` (the relay reads the sample's fields).
  void read_counters(RelaySample& sample);
  /// The surface into `frame` from surface.embedding (re-read when surface.revision changes: a cut)
  /// and surface.nodes: its points mapped, its nodes and embedding for a viewer. Its vectors keep
  /// their capacity: between cuts no allocation after the first. Throws FmuError for outputs that do
  /// not decode.
  void read_surface(SurfaceFrame& frame);
  /// The same without the mapping, for a consumer in another thread (SurfaceMapping::complete): the
  /// embedding's bytes (copied when surface.revision changes, into a buffer no frame holds any more:
  /// RecycledBytes) and the nodes. Issue 42: after a cut the decode and the mapping of the organ's
  /// fine surface took 1.5-2.5 ms of the step's slot.
  void read_surface_unmapped(SurfaceFrame& frame);
  /// Whether surface.revision moved since the embedding was last read (a cut re-meshed the surface:
  /// the next read copies the embedding).
  [[nodiscard]] bool surface_remeshed();
  /// Whether the Tissue still prepares its re-meshed surface after the last step (its
  /// surface.preparing; false for an FMU without it): a read now would wait for it.
  [[nodiscard]] bool surface_preparing();
  /// Gives `frame` room for twice the surface at rest, so that reading into it rarely allocates.
  void reserve(SurfaceFrame& frame) const;
  /// Axis-aligned box of the tet mesh at rest (after initialization), whichever surface is drawn.
  [[nodiscard]] const std::array<double, 3>& rest_lower() const { return m_rest_lower; }
  [[nodiscard]] const std::array<double, 3>& rest_upper() const { return m_rest_upper; }
  [[nodiscard]] double blade_length_m() const { return m_blade_length_m; }
  [[nodiscard]] Fmu3Instance& instance() { return m_instance; }

 private:
  [[nodiscard]] std::uint64_t surface_revision();  // the Tissue's surface.revision now
  /// Whether the embedding's bytes held are those of surface revision `revision`.
  [[nodiscard]] bool embedding_read_at(std::uint64_t revision) const {
    return m_embedding_bytes && revision == m_embedding_revision;
  }

  Fmu3Instance m_instance;
  fmi3ValueReference m_tool_position, m_tool_orientation, m_tool_mode;
  fmi3ValueReference m_revision, m_embedding_vr, m_nodes_vr, m_cut_tets, m_enriched;
  std::optional<fmi3ValueReference> m_prepare_vr;    // surface.prepareAfterStep, when the FMU has it
  std::optional<fmi3ValueReference> m_preparing_vr;  // surface.preparing, when the FMU has it
  bool m_prepare = false;                           // its value as last set
  std::shared_ptr<const std::vector<std::uint8_t>> m_embedding_bytes;  // of the last revision read
  RecycledBytes m_embedding_copies;  // m_embedding_bytes's buffers
  std::uint64_t m_embedding_revision = 0;
  std::shared_ptr<const ports::SurfaceEmbedding> m_embedding;            // of the first read (reserve())
  SurfaceMapping m_mapping;  // read_surface()'s
  ports::SurfaceNodes m_nodes;
  std::array<double, 3> m_rest_lower{}, m_rest_upper{};
  double m_blade_length_m = 0.0;
};

class HapticLink {
 public:
  HapticLink(const Fmu3& fmu, const std::vector<ParameterSetting>& parameters);

  void set_device(const DevicePose& pose);
  DoStepResult step(double time_s, double step_s);
  void read(HapticOutputs& outputs);
  [[nodiscard]] double max_force_n() const { return m_max_force_n; }
  [[nodiscard]] double max_force_rate_n_per_s() const { return m_max_force_rate_n_per_s; }
  [[nodiscard]] Fmu3Instance& instance() { return m_instance; }

 private:
  Fmu3Instance m_instance;
  std::array<fmi3ValueReference, 2> m_device_float{};  // position, orientation
  fmi3ValueReference m_device_mode;
  std::array<fmi3ValueReference, 3> m_out_float{};  // tool position, tool orientation, device force
  std::array<fmi3ValueReference, 2> m_out_energy{};
  fmi3ValueReference m_out_mode;
  std::array<fmi3ValueReference, 3> m_out_flags{};
  double m_max_force_n = 0.0, m_max_force_rate_n_per_s = 0.0;
};

}  // namespace tissue::host
