// The HapticLoop FMU's model behind the FMI layer (fmi3/model.hpp): the haptic renderer
// (libtissue/haptic) ticked every stepSize; the device pose in, the tool pose for the tissue and the
// device force out. A new tissue.time marks a new tissue sample. Range checks are the renderer's
// own validate(). No allocation in doStep or in setting inputs (the host's haptic thread calls them
// at 1 kHz).
#pragma once

#include "fmi3/model.hpp"
#include "haptic/haptic_renderer.hpp"
#include "haptic_loop/variables.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <span>

namespace tissue::haptic_fmu {

/// The renderer's settings from the FMU's parameters (throws tissue::ParameterError when refused).
haptic::RendererSettings renderer_settings(const fmi3::ValueStore& values);
/// Every parameter checked as a set of them is (the renderer's ranges, stepSize and workspace.scale > 0):
/// throws tissue::ParameterError or fmi3::VariableError with the reason. Also the Python module's
/// HapticLoop's check (python/haptic_loop.cpp), so that both refuse the same values.
void check_parameters(const fmi3::ValueStore& values);
/// tool.position: workspace.offset + workspace.scale * the device's position.
Eigen::Vector3d tool_position(const fmi3::ValueStore& values, const Eigen::Vector3d& device_position_m);

class HapticModel final : public fmi3::Model {
 public:
  HapticModel(const fmi3::ModelContext& context, const fmi3::ValueStore& values);

  void validate_parameters(const fmi3::ValueStore& values) const override;
  void parameters_changed() override;
  void enter_initialization_mode(double start_time_s) override;
  void exit_initialization_mode() override;
  fmi3::StepOutcome do_step(double current_time_s, double step_s) override;
  void reset() override;

  void get_float64(const fmi3::VariableInfo& info, std::span<double> values) override;
  void get_int64(const fmi3::VariableInfo& info, std::span<std::int64_t> values) override;
  void get_uint64(const fmi3::VariableInfo& info, std::span<std::uint64_t> values) override;
  void get_boolean(const fmi3::VariableInfo& info, std::span<bool> values) override;

  [[nodiscard]] std::unique_ptr<fmi3::ModelState> save() const override;
  void restore(const fmi3::ModelState& state) override;
  void serialize(const fmi3::ModelState& state, serial::ByteWriter& writer) const override;
  [[nodiscard]] std::unique_ptr<fmi3::ModelState> deserialize(serial::ByteReader& reader) const override;

 private:
  [[nodiscard]] Eigen::Vector3d tool_position() const;
  void take_tissue_sample();

  fmi3::ModelContext m_context;
  const fmi3::ValueStore& m_values;
  haptic::HapticRenderer m_renderer;
  double m_time_s = 0.0;
  bool m_has_sample_time = false;
  double m_sample_time_s = 0.0;
  std::uint64_t m_samples_received = 0;
  std::uint64_t m_samples_refused = 0;
};

}  // namespace tissue::haptic_fmu
