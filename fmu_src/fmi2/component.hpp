// One FMI 2.0 component: the FMI 3.0 layer's Instance (fmi3/instance.hpp: the state table, the
// stored values, the model, FMU states, logging) seen through the ScalarLayout, so that 2.0's
// scalar calls become the layer's whole-variable calls. What 2.0 adds: the start time from
// fmi2SetupExperiment, and a set of one element at a time.
//
// An array whose norm the schema bounds (a quaternion, VariableInfo::min_norm) may pass through
// zero while an importer sets it one element per call (FMPy and fmusim do): such a value is held
// here, read back as set, and handed to the layer, with its check, once it passes or before the
// next use (exitInitializationMode, doStep), where a value that still fails is an error.
#pragma once

#include "fmi2/scalar_layout.hpp"
#include "fmi3/instance.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace tissue::fmi2 {

class Component {
 public:
  Component(const ScalarLayout& layout, std::string name, std::string resource_path, bool logging_on,
            fmi3::StatusLogger logger);

  [[nodiscard]] fmi3::Instance& instance() { return m_instance; }
  [[nodiscard]] const ScalarLayout& layout() const { return m_layout; }

  void setup_experiment(double start_time_s);
  void enter_initialization_mode() { m_instance.enter_initialization_mode(m_start_time_s); }
  void exit_initialization_mode();
  fmi3::Status do_step(double current_time_s, double step_s);
  [[nodiscard]] double last_successful_time_s() const { return m_last_successful_time_s; }
  void reset();
  /// A saved FMU state back (values held while being set are dropped: the state has its own).
  void restore(const fmi3::InstanceState& saved);

  /// T: double (Real), int (Integer and Enumeration), int as fmi2Boolean (`boolean` true), const char*.
  template <class T>
  void get(std::span<const std::uint32_t> vrs, std::span<T> values, ScalarType expected);
  template <class T>
  void set(std::span<const std::uint32_t> vrs, std::span<const T> values, ScalarType expected);

 private:
  struct Pending {
    const VariableInfo* variable;
    std::vector<double> values;
  };
  const Scalar& scalar(std::uint32_t vr, ScalarType expected) const;
  void flush_pending();

  const ScalarLayout& m_layout;
  fmi3::Instance m_instance;
  double m_start_time_s = 0.0;
  double m_last_successful_time_s = 0.0;
  std::vector<Pending> m_pending;
  std::vector<std::string> m_strings;  // what fmi2GetString's pointers point to, until the next call
};

}  // namespace tissue::fmi2
