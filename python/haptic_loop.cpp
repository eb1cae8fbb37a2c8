// tissue.HapticLoop (see haptic_loop.hpp).
#include "haptic_loop.hpp"

#include "arrays.hpp"
#include "haptic_loop/haptic_model.hpp"
#include "haptic_loop/variables.hpp"

#include <pybind11/stl.h>

#include <algorithm>
#include <cctype>
#include <span>
#include <vector>

namespace py = pybind11;

namespace tissue::python {
namespace {

using fmi3::VariableInfo;
using fmi3::VariableType;

const fmi3::ModelDescription& description() { return haptic_fmu::haptic_loop_model_description(); }

bool is_parameter(const VariableInfo& info) { return info.causality == fmi3::Causality::parameter; }

const VariableInfo* find_keyword(const std::string& keyword) {
  for (const VariableInfo& info : description().variables) {
    if (is_parameter(info) && python_keyword(info) == keyword) return &info;
  }
  return nullptr;
}

// The constructor's documentation: every keyword with its default, unit and the FMU's description.
std::string haptic_loop_doc() {
  std::string doc =
      "The HapticLoop FMU's 1 kHz haptic renderer. Keyword arguments only, every one optional: the FMU's "
      "parameters (SI units), with the FMU's defaults and ranges:\n";
  for (const VariableInfo& info : description().variables) {
    if (!is_parameter(info)) continue;
    const bool boolean = info.type == VariableType::boolean;
    doc += "  " + python_keyword(info) + "=" +
           (boolean ? (info.start == "true" ? "True" : "False") : std::string(info.start));
    if (!info.unit.empty() && info.unit != "1") doc += " [" + std::string(info.unit) + "]";
    if (!info.min.empty()) doc += " >= " + std::string(info.min);
    doc += " (FMU: " + std::string(info.name) + "): " + std::string(info.description) + "\n";
  }
  return doc;
}

py::type_error wrong_type(const std::string& keyword, const char* expected, const py::handle& value) {
  return py::type_error(keyword + " must be " + expected + ", got " +
                        std::string(py::str(py::type::of(value).attr("__name__"))));
}

// A 3 x 3 matrix of a sample dict (row-major, as Tissue.tool_contact gives it).
Eigen::Matrix3d matrix3(const py::handle& value, const char* key) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
    throw std::invalid_argument(std::string("sample: ") + key + " must be a 3 x 3 matrix");
  }
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = a.at(r, c);
  }
  return m;
}

// The vector of a sample dict's key, or nullptr.
Eigen::Vector3d* vector_field(haptic::TissueSample& s, const std::string& key) {
  if (key == "point_m") return &s.contact_point_m;
  if (key == "normal") return &s.contact_normal;
  if (key == "force_on_tool_n") return &s.force_on_tool_n;
  if (key == "tool_position_m") return &s.tool_position_m;
  return nullptr;
}

// One key of a sample dict into `s`; false for a key it does not know.
bool set_field(haptic::TissueSample& s, const std::string& key, const py::handle& value) {
  if (key == "active") {
    s.contact_active = value.cast<bool>();
  } else if (key == "near") {
    s.surface_near = value.cast<bool>();
  } else if (Eigen::Vector3d* v = vector_field(s, key)) {
    *v = to_vector3(value.cast<std::array<double, 3>>());
  } else if (key == "stiffness_n_per_m") {
    s.contact_stiffness_n_per_m = matrix3(value, "stiffness_n_per_m");
  } else if (key == "damping_n_s_per_m") {
    s.contact_damping_n_s_per_m = matrix3(value, "damping_n_s_per_m");
  } else if (key == "blade_depth_m") {
    s.blade_depth_m = value.cast<double>();
  } else if (key == "time_s") {
    s.time_s = value.cast<double>();
  } else {
    return key == "depth_m";  // Tissue.tool_contact's, not part of the sample
  }
  return true;
}

// A sample from a dict with Tissue.tool_contact's keys (depth_m ignored) and tool_position_m,
// blade_depth_m, time_s; a key left out is zero (false). An unknown key or a value of the wrong type
// is a TypeError.
haptic::TissueSample sample_from_dict(const py::dict& fields) {
  haptic::TissueSample s;
  for (const auto& [key, value] : fields) {
    const std::string name = py::str(key);
    bool known = false;
    try {
      known = set_field(s, name, value);
    } catch (const py::cast_error&) {
      throw py::type_error("set_sample: " + name + " has the wrong type (" +
                           std::string(py::str(py::type::of(value).attr("__name__"))) + ")");
    }
    if (!known) {
      throw py::type_error("set_sample: unknown key '" + name +
                           "' (active, near, point_m, normal, force_on_tool_n, stiffness_n_per_m, damping_n_s_per_m, "
                           "tool_position_m, blade_depth_m, time_s)");
    }
  }
  return s;
}

}  // namespace

std::string python_keyword(const VariableInfo& parameter) {
  std::string keyword;
  for (const char c : parameter.name) {
    if (c == '.') {
      keyword += '_';
    } else if (std::isupper(static_cast<unsigned char>(c)) != 0) {
      keyword += '_';
      keyword += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else {
      keyword += c;
    }
  }
  if (parameter.unit.empty() || parameter.unit == "1") return keyword;
  keyword += '_';
  for (const char c : parameter.unit) {
    if (c == '/') {
      keyword += "_per_";
    } else if (c == '.') {
      keyword += '_';
    } else {
      keyword += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  return keyword;
}

haptic::TissueSample tissue_sample(const Tissue& tissue) {
  const ToolContact contact = tissue.tool_contact();
  haptic::TissueSample s;
  s.time_s = tissue.time_s();
  s.contact_active = contact.active;
  s.surface_near = contact.near;
  s.contact_point_m = contact.point_m;
  s.contact_normal = contact.normal;
  s.force_on_tool_n = contact.force_on_tool_n;
  s.contact_stiffness_n_per_m = contact.stiffness_n_per_m;
  s.contact_damping_n_s_per_m = contact.damping_n_s_per_m;
  s.tool_position_m = tissue.applied_tool_position_m();
  s.blade_depth_m = tissue.blade_depth_m();
  return s;
}

PyHapticLoop::PyHapticLoop(const py::kwargs& keywords) : m_values(description()) {
  m_values.set_starts();
  for (const auto& [key, value] : keywords) set_keyword(py::str(key), value);
  m_renderer = haptic::HapticRenderer(haptic_fmu::renderer_settings(m_values));
  m_tool_position_m = haptic_fmu::tool_position(m_values, Eigen::Vector3d::Zero());
}

// One keyword into the FMU's store, then the FMU's checks: the starts pass them, so a refusal is this
// keyword's. The message names the keyword, then the FMU's parameter as the FMU does.
void PyHapticLoop::set_keyword(const std::string& keyword, const py::handle& value) {
  const VariableInfo* info = find_keyword(keyword);
  if (info == nullptr) {
    throw py::type_error("HapticLoop() got an unexpected keyword argument '" + keyword +
                         "' (help(tissue.HapticLoop) lists them)");
  }
  try {
    if (info->type == VariableType::boolean) {
      if (!py::isinstance<py::bool_>(value)) throw wrong_type(keyword, "True or False", value);
      const bool flag = value.cast<bool>();
      m_values.write<bool>(*info, std::span<const bool>(&flag, 1));
    } else if (info->rank == 0) {
      if (py::isinstance<py::bool_>(value)) throw wrong_type(keyword, "a number", value);
      double number = 0.0;
      try {
        number = value.cast<double>();
      } catch (const py::cast_error&) {
        throw wrong_type(keyword, "a number", value);
      }
      m_values.write<double>(*info, std::span<const double>(&number, 1));
    } else {
      std::vector<double> numbers;
      try {
        numbers = value.cast<std::vector<double>>();
      } catch (const py::cast_error&) {
        throw wrong_type(keyword, "a sequence of numbers", value);
      }
      m_values.write<double>(*info, numbers);
    }
    haptic_fmu::check_parameters(m_values);
  } catch (const std::invalid_argument& error) {  // fmi3::VariableError, tissue::ParameterError
    throw py::value_error(keyword + ": " + error.what());
  }
}

void PyHapticLoop::set_sample(const haptic::TissueSample& sample) {
  m_renderer.set_sample(sample);
  ++m_samples_received;
}

py::array_t<double> PyHapticLoop::tick(const std::array<double, 3>& device_position_m, std::optional<double> dt_s,
                                       const std::string& mode) {
  const std::optional<ToolMode> tool_mode = tool_mode_named(mode);
  if (!tool_mode) throw std::invalid_argument("tool mode '" + mode + "' is not none, probe or scalpel");
  const double tick_s = dt_s.value_or(m_values.float64(static_cast<fmi3::ValueReference>(haptic_fmu::Vr::step_size)));
  const Eigen::Vector3d tool_m = haptic_fmu::tool_position(m_values, to_vector3(device_position_m));
  const Eigen::Vector3d force_n = m_renderer.tick(tool_m, *tool_mode, tick_s);
  m_tool_position_m = tool_m;
  m_time_s += tick_s;
  return vector3(force_n);
}

void PyHapticLoop::reset() {
  m_renderer.reset();
  m_tool_position_m = haptic_fmu::tool_position(m_values, Eigen::Vector3d::Zero());
  m_time_s = 0.0;
  m_samples_received = 0;
}

py::dict PyHapticLoop::parameters() const {
  py::dict out;
  for (const VariableInfo& info : description().variables) {
    if (!is_parameter(info)) continue;
    const auto vr = info.vr;
    if (info.type == VariableType::boolean) {
      out[py::str(python_keyword(info))] = m_values.boolean(vr);
    } else if (info.rank == 0) {
      out[py::str(python_keyword(info))] = m_values.float64(vr);
    } else {
      const std::span<const double> a = m_values.float64_array(vr);
      out[py::str(python_keyword(info))] = py::tuple(py::cast(std::vector<double>(a.begin(), a.end())));
    }
  }
  return out;
}

namespace {

// What the FMU outputs after a tick, as read-only properties (vectors as numpy arrays, copies).
void bind_outputs(py::class_<PyHapticLoop>& loop) {
  using L = PyHapticLoop;
  loop.def_property_readonly(
          "force_n", [](const L& l) { return vector3(l.last_tick().commanded_force_n); },
          "device.force: the force the last tick commanded [N] (clamped, rate limited, passive)")
      .def_property_readonly(
          "contact_force_n", [](const L& l) { return vector3(l.last_tick().contact_force_n); },
          "force.contact: the contact part before the limits [N]")
      .def_property_readonly(
          "cutting_force_n", [](const L& l) { return vector3(l.last_tick().cutting_force_n); },
          "force.cutting: the cutting part before the limits [N]")
      .def_property_readonly(
          "passivity_force_n", [](const L& l) { return vector3(l.last_tick().passivity_force_n); },
          "force.passivity: the passivity controller's share of force_n [N]")
      .def_property_readonly(
          "velocity_m_per_s", [](const L& l) { return vector3(l.last_tick().velocity_m_per_s); },
          "The hand's velocity as the loop's low-pass filter sees it [m/s]")
      .def_property_readonly(
          "tool_position_m", [](const L& l) { return vector3(l.tool_position_m()); },
          "tool.position: the tool's position for Tissue.set_tool (workspace_offset_m + "
          "workspace_scale x the device's position) [m]")
      .def_property_readonly(
          "observed_energy_j", [](const L& l) { return l.renderer().observed_energy_j(); },
          "passivity.observedEnergy: energy the loop has absorbed from the hand [J]; negative: "
          "it gave energy")
      .def_property_readonly(
          "dissipated_energy_j", [](const L& l) { return l.renderer().dissipated_energy_j(); },
          "passivity.dissipatedEnergy: energy the passivity controller has dissipated [J]")
      .def_property_readonly(
          "passivity_damping_n_s_per_m", [](const L& l) { return l.last_tick().damping_n_s_per_m; },
          "The damping the passivity controller asked for in the last tick (0: it did not act)")
      .def_property_readonly(
          "passivity_acted", [](const L& l) { return l.last_tick().passivity_acted; },
          "passivity.acted: the controller added damping in the last tick")
      .def_property_readonly(
          "force_clamped", [](const L& l) { return l.last_tick().clamped; },
          "force.clamped: the last tick's force was clamped to device_max_force_n")
      .def_property_readonly(
          "force_rate_limited", [](const L& l) { return l.last_tick().rate_limited; },
          "force.rateLimited: the last tick's change was limited to device_max_force_rate_n_per_s")
      .def_property_readonly(
          "position_rejected", [](const L& l) { return l.last_tick().position_rejected; },
          "The last tick's device position was not finite (no contact rendered, the force "
          "released at the rate limit)")
      .def_property_readonly("has_sample", [](const L& l) { return l.renderer().has_sample(); })
      .def_property_readonly("samples_received", &L::samples_received, "tissue.samplesReceived")
      .def_property_readonly("time_s", &L::time_s, "The ticks' lengths summed since construction or reset() [s]");
}

}  // namespace

py::class_<PyHapticLoop> bind_haptic_loop(py::module_& module) {
  static const std::string constructor_doc = haptic_loop_doc();
  py::class_<PyHapticLoop> loop(module, "HapticLoop");
  loop.def(py::init([](const py::args& args, const py::kwargs& keywords) {
             if (!args.empty()) throw py::type_error("HapticLoop() takes keyword arguments only");
             return PyHapticLoop(keywords);
           }),
           constructor_doc.c_str())
      .def(
          "set_sample", [](PyHapticLoop& l, const py::dict& fields) { l.set_sample(sample_from_dict(fields)); },
          py::arg("sample"),
          "A tissue sample as a dict: Tissue.tool_contact's keys and tool_position_m (x0), blade_depth_m, time_s")
      .def("tick", &PyHapticLoop::tick, py::arg("device_position_m"), py::arg("dt_s") = py::none(),
           py::arg("mode") = "probe",
           "One haptic tick: the device's position [m], the tick [s] (step_size_s if None), the tool mode ('none', "
           "'probe', 'scalpel'); returns the force to command on the device [N]")
      .def("reset", &PyHapticLoop::reset, "Back to the state after construction (no sample, no motion, no force)")
      .def_property_readonly("parameters", &PyHapticLoop::parameters, "{keyword: value} of every parameter")
      .def_property_readonly_static(
          "fmu_names",
          [](const py::object&) {
            py::dict names;
            for (const VariableInfo& info : description().variables) {
              if (is_parameter(info)) names[py::str(python_keyword(info))] = std::string(info.name);
            }
            return names;
          },
          "{keyword: the HapticLoop FMU's parameter}");
  bind_outputs(loop);
  return loop;
}

}  // namespace tissue::python
