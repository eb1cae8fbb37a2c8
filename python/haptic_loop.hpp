// tissue.HapticLoop: the HapticLoop FMU's haptic renderer (libtissue/haptic) from Python, built as the
// FMU builds it: its parameters are the FMU's (fmu_src/haptic_loop/variables.hpp), stored in the FMU's
// own ValueStore from their start values, checked by the FMU's check_parameters() and turned into the
// renderer's settings by its renderer_settings(). Each Python keyword is derived from the FMU
// parameter's name and unit (python_keyword()), so the keywords, defaults and ranges are the FMU's and
// are written nowhere else. Errors: ValueError naming the keyword (a value out of range, not finite, a
// bad sample or tick), TypeError (an unknown keyword, a value of the wrong type).
#pragma once

#include "core/tissue.hpp"
#include "fmi3/value_store.hpp"
#include "fmi3/variable_table.hpp"
#include "haptic/haptic_renderer.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace tissue::python {

/// The Python keyword of an FMU parameter: its name in snake_case, then its unit's ("N.s/m" -> n_s_per_m;
/// none for "1"): device.maxForce [N] -> device_max_force_n, contact.damping [N.s/m] ->
/// contact_damping_n_s_per_m, passivity.control -> passivity_control.
std::string python_keyword(const fmi3::VariableInfo& parameter);

/// What the Tissue FMU sends the HapticLoop after a step (ports/tissue_sample.hpp), read from the core:
/// the complete contact output (Tissue::tool_contact), the tool position the step applied, the blade's
/// depth and the time.
haptic::TissueSample tissue_sample(const Tissue& tissue);

class PyHapticLoop {
 public:
  /// From keyword arguments (the FMU's parameters by python_keyword(); the rest keep their start values).
  explicit PyHapticLoop(const pybind11::kwargs& keywords);

  /// A new tissue sample (zero-order hold until the next); std::invalid_argument for one the renderer
  /// refuses (the previous one is kept).
  void set_sample(const haptic::TissueSample& sample);
  /// One tick: the device's position [m], the tick [s] (stepSize unless given), the tool mode; the
  /// force to command on the device [N].
  pybind11::array_t<double> tick(const std::array<double, 3>& device_position_m, std::optional<double> dt_s,
                                 const std::string& mode);
  /// Back to the state after construction (no sample, no motion, no force, zero energy).
  void reset();

  /// {keyword: value} of every parameter.
  [[nodiscard]] pybind11::dict parameters() const;
  [[nodiscard]] const haptic::TickReport& last_tick() const { return m_renderer.last_tick(); }
  [[nodiscard]] const haptic::HapticRenderer& renderer() const { return m_renderer; }
  [[nodiscard]] const Eigen::Vector3d& tool_position_m() const { return m_tool_position_m; }
  [[nodiscard]] double time_s() const { return m_time_s; }
  [[nodiscard]] std::uint64_t samples_received() const { return m_samples_received; }

 private:
  void set_keyword(const std::string& keyword, const pybind11::handle& value);

  fmi3::ValueStore m_values;
  haptic::HapticRenderer m_renderer;
  Eigen::Vector3d m_tool_position_m = Eigen::Vector3d::Zero();
  double m_time_s = 0.0;
  std::uint64_t m_samples_received = 0;
};

/// Adds tissue.HapticLoop to the module; set_sample from a tissue.Tissue is added where Tissue is bound.
pybind11::class_<PyHapticLoop> bind_haptic_loop(pybind11::module_& module);

}  // namespace tissue::python
