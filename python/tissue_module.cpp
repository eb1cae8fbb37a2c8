// The Python module `tissue` (pybind11) over the core: a Tissue made from a mesh (the embedded frog,
// a .veg, .node/.ele or .msh file, or a box of cubes) with material, damping, gravity, the fixed
// region and the integrator as keyword arguments in SI units, or from a tissue-host scenario (its
// Tissue FMU parameters, through the FMU's own store and builder; its scripted hand's path); step it, move the probe or the
// scalpel, read the state, the contact, the drawn surface and the cut state as numpy arrays, save
// and restore the state as bytes. Errors come back as Python exceptions with the core's message:
// ValueError for a bad setting or pose, RuntimeError for a failed step or a state that cannot be
// restored. The core's arrays are copied out (numpy owns them), so nothing dangles after a step.
// The HapticLoop FMU's renderer is tissue.HapticLoop (haptic_loop.hpp), fed from a Tissue here.
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/material/region_materials.hpp"
#include "core/tissue.hpp"
#include "core/tissue_settings_schema.hpp"
#include "core/tissue_snapshot_io.hpp"
#include "device/scripted_device.hpp"
#include "arrays.hpp"
#include "fmi3/value_store.hpp"
#include "haptic_loop.hpp"
#include "quasi_static.hpp"
#include "resources/default_mesh.hpp"
#include "scenario/scenario.hpp"
#include "tissue_fmu/tissue_model.hpp"
#include "tissue_fmu/variables.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <climits>
#include <map>
#include <cstdint>
#include <variant>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace py = pybind11;

namespace tissue::python {
namespace {

using Array = py::array_t<double>;

// An (rows x columns) float64 array holding a copy of `values` (row-major).
Array matrix(const double* values, py::ssize_t rows, py::ssize_t columns) {
  Array out({rows, columns});
  std::copy(values, values + rows * columns, out.mutable_data());
  return out;
}

ToolMode tool_mode(const std::string& mode) {
  if (mode == "none") return ToolMode::none;
  if (mode == "probe") return ToolMode::probe;
  if (mode == "scalpel") return ToolMode::scalpel;
  throw ParameterError("tool mode '" + mode + "' is not none, probe or scalpel");
}

std::string tool_mode_name(ToolMode mode) {
  return mode == ToolMode::probe ? "probe" : mode == ToolMode::scalpel ? "scalpel" : "none";
}

// The keyword arguments Python sets in its own way; the others are the settings schema's Python
// keywords (core/tissue_settings_schema.hpp), with its defaults.
struct PythonOnly {
  std::optional<std::array<int, 3>> box_cells;  // a box of cubes instead of a mesh
  double box_edge_m = 0.01;
  std::optional<std::vector<int>> fixed_vertices;  // instead of the fixed slab
  /// Materials by region name (issue 25): {"tumour": {"young_modulus_pa": 1e6, ...}}; a key left out
  /// keeps the body's value (young_modulus_pa, poisson_ratio, density_kg_per_m3, damping_alpha_per_s).
  std::map<std::string, std::map<std::string, double>> regions;
};

// A keyword's value as the schema's type, or TypeError.
SettingValue python_value(const SettingInfo& setting, const py::handle& value) {
  const auto wrong = [&]() -> py::type_error {
    return py::type_error(std::string(setting.python_keyword) + " must be " + expected_value_text(setting) + ", got " +
                          std::string(py::str(py::type::of(value).attr("__name__"))));
  };
  try {
    switch (setting.type) {
      case SettingType::real:
        if (py::isinstance<py::bool_>(value)) throw wrong();
        return value.cast<double>();
      case SettingType::integer:
        if (py::isinstance<py::bool_>(value) || py::isinstance<py::float_>(value)) throw wrong();
        return value.cast<std::int64_t>();
      case SettingType::boolean:
        if (!py::isinstance<py::bool_>(value)) throw wrong();
        return value.cast<bool>();
      case SettingType::vector3:
        return value.cast<std::array<double, 3>>();
      case SettingType::enumeration:
      case SettingType::text:
        if (!py::isinstance<py::str>(value)) throw wrong();
        return value.cast<std::string>();
    }
  } catch (const py::cast_error&) {
    throw wrong();
  }
  throw wrong();
}

// The constructor's documentation: the Python keywords and the schema's keywords with their types,
// units, defaults and ranges.
std::string tissue_doc() {
  std::string doc =
      "A tissue. Keyword arguments only (SI units), every one optional:\n"
      "  box=(nx, ny, nz): a box of cubes of box_edge_m (default 0.01 m) instead of the mesh\n"
      "  fixed_vertices=[...]: the fixed vertices by index, instead of fixed_axis and fixed_fraction\n"
      "  regions={name: {young_modulus_pa, poisson_ratio, density_kg_per_m3, damping_alpha_per_s}}: the "
      "materials of the mesh file's regions by name\n";
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.python_keyword.empty()) continue;
    doc += "  " + std::string(setting.python_keyword) + "=" + to_text(start_value(setting));
    if (setting.type == SettingType::enumeration) doc += " (" + list_names(setting.items) + ")";
    if (!setting.unit.empty() && setting.unit != "1") doc += " [" + std::string(setting.unit) + "]";
    if (const std::string range = range_text(setting); !range.empty()) doc += " " + range;
    doc += ": " + std::string(setting.description) + "\n";
  }
  return doc;
}

// The regions' materials the `regions` argument sets, on top of the body's material.
std::vector<RegionMaterial> region_materials(const std::map<std::string, std::map<std::string, double>>& regions,
                                             const Material& base) {
  std::vector<RegionMaterial> materials;
  for (const auto& [name, keys] : regions) {
    RegionMaterial region{name, base};
    for (const auto& [key, value] : keys) {
      const std::span<const MaterialProperty> properties = material_properties();
      const auto property = std::find_if(properties.begin(), properties.end(),
                                         [&](const MaterialProperty& p) { return p.si_name == key; });
      if (property == properties.end()) {
        std::string names;
        for (const MaterialProperty& p : properties) names += (names.empty() ? "" : ", ") + std::string(p.si_name);
        throw ParameterError("regions[\"" + name + "\"]: unknown key \"" + key + "\" (" + names + ")");
      }
      property->set(region.material, value);
    }
    materials.push_back(std::move(region));
  }
  return materials;
}

// A Tissue behind a pointer: restoring a state with other cuts replaces it (restore_or_replay).
class PyTissue {
 public:
  explicit PyTissue(std::unique_ptr<Tissue> tissue) : m_tissue(std::move(tissue)) {}
  PyTissue(const TissueParameters& parameters, const PythonOnly& extra) {
    TetMesh mesh = extra.box_cells ? make_box_mesh((*extra.box_cells)[0], (*extra.box_cells)[1],
                                                   (*extra.box_cells)[2], extra.box_edge_m)
                                   : load_mesh(parameters.mesh);
    TissueParameters resolved = parameters;
    if (extra.fixed_vertices) resolved.fixed_axis = -1;
    TissueSettings settings = resolve_settings(resolved, &mesh);
    if (extra.fixed_vertices) settings.body.fixed_vertices = *extra.fixed_vertices;
    if (!extra.regions.empty()) settings.body.region_materials = region_materials(extra.regions, settings.body.material);
    if (parameters.render_surface != NO_RENDER_SURFACE) {
      settings.render_surface = std::make_shared<const TriangleSurface>(load_render_surface(parameters.render_surface));
    }
    m_tissue = std::make_unique<Tissue>(std::move(mesh), settings);
  }

  // From keyword arguments: the Python-only ones, then the schema's.
  static PyTissue from_keywords(const py::kwargs& keywords) {
    PythonOnly extra;
    TissueParameters parameters = default_parameters();
    for (const auto& [key, value] : keywords) {
      const std::string name = py::str(key);
      if (name == "box") {
        if (!value.is_none()) extra.box_cells = value.cast<std::array<int, 3>>();
      } else if (name == "box_edge_m") {
        extra.box_edge_m = value.cast<double>();
      } else if (name == "fixed_vertices") {
        if (!value.is_none()) extra.fixed_vertices = value.cast<std::vector<int>>();
      } else if (name == "regions") {
        extra.regions = value.cast<std::map<std::string, std::map<std::string, double>>>();
      } else if (const SettingInfo* setting = find_python_setting(name)) {
        try {
          set_value(*setting, parameters, python_value(*setting, value));
        } catch (const ParameterError& error) {  // named as Python names it, then as the FMU does
          throw ParameterError(name + ": " + error.what());
        }
      } else {
        throw py::type_error("Tissue() got an unexpected keyword argument '" + name + "' (help(tissue.Tissue) lists them)");
      }
    }
    return {parameters, extra};
  }

  void set_tool(const std::array<double, 3>& position_m, const std::array<double, 4>& orientation_wxyz,
                const std::string& mode) {
    m_tissue->set_tool({to_vector3(position_m),
                        Eigen::Quaterniond(orientation_wxyz[0], orientation_wxyz[1], orientation_wxyz[2],
                                           orientation_wxyz[3]),
                        tool_mode(mode)});
  }

  // `steps` steps; the last one's report.
  py::dict step(int steps) {
    if (steps < 1) throw ParameterError("steps must be >= 1, got " + std::to_string(steps));
    TissueStepReport report;
    {
      py::gil_scoped_release release;  // other Python threads run while the tissue steps
      for (int n = 0; n < steps; ++n) report = m_tissue->step();
    }
    py::dict out;
    out["newton_iterations"] = report.dynamics.newton_iterations;
    out["linear_iterations"] = report.dynamics.linear_iterations;
    out["energy_guarded"] = report.dynamics.energy_guarded;
    out["newly_cut_tets"] = report.cut.newly_cut_tets;
    out["new_enriched_dofs"] = report.enrichment.new_enriched_dofs;
    out["matrix_relayout"] = report.enrichment.matrix_relayout;
    out["parked_rows"] = report.parked_rows;
    out["assembly_s"] = report.dynamics.assembly_s;
    out["solve_s"] = report.dynamics.solve_s;
    out["cut_s"] = report.cut_s;
    out["enrich_s"] = report.enrich_s;
    out["contact_s"] = report.contact_s;
    out["guard_s"] = report.dynamics.guard_s;
    out["positions_s"] = report.positions_s;
    out["total_s"] = report.total_s;
    return out;
  }

  [[nodiscard]] double time_s() const { return m_tissue->time_s(); }
  [[nodiscard]] const Tissue& core() const { return *m_tissue; }
  [[nodiscard]] int vertex_count() const { return m_tissue->body().mesh().vertex_count(); }
  [[nodiscard]] int tet_count() const { return m_tissue->body().mesh().tet_count(); }
  /// The mesh's regions and their resolved materials:
  /// {name: (young_modulus_pa, poisson_ratio, density_kg_per_m3, damping_alpha_per_s)}.
  [[nodiscard]] std::map<std::string, std::array<double, 4>> regions() const {
    std::map<std::string, std::array<double, 4>> out;
    const DeformableBody& body = m_tissue->body();
    for (size_t r = 0; r < body.mesh().regions.size(); ++r) {
      const Material& m = body.materials()[r];
      out[body.mesh().regions[r].name] = {m.young_modulus_pa, m.poisson_ratio, m.density_kg_per_m3,
                                          body.region_mass_damping_per_s()[r]};
    }
    return out;
  }
  [[nodiscard]] int dof_count() const { return m_tissue->body().dof_count(); }
  [[nodiscard]] int parked_rows() const { return m_tissue->body().parked_row_count(); }
  [[nodiscard]] int cut_tets() const { return m_tissue->body().cut_tet_count(); }
  [[nodiscard]] int enriched_vertices() const { return m_tissue->body().enriched_dof_count(); }
  [[nodiscard]] double kinetic_energy_j() const { return m_tissue->kinetic_energy_j(); }
  [[nodiscard]] double elastic_energy_j() { return m_tissue->elastic_energy_j(); }

  // Positions of the mesh vertices (vertex_count x 3) [m].
  [[nodiscard]] Array positions_m() const {
    Eigen::VectorXd positions;
    m_tissue->vertex_positions(positions);
    return matrix(positions.data(), positions.size() / 3, 3);
  }
  // Positions at rest (vertex_count x 3) [m].
  [[nodiscard]] Array rest_positions_m() const {
    const std::vector<Eigen::Vector3d>& rest = m_tissue->body().mesh().rest_positions_m;
    Array out({static_cast<py::ssize_t>(rest.size()), py::ssize_t{3}});
    for (std::size_t v = 0; v < rest.size(); ++v) std::copy(rest[v].data(), rest[v].data() + 3, out.mutable_data(v, 0));
    return out;
  }
  // The drawn surface: (points m x 3 [m], triangles k x 3 indices into points): the mesh's surface
  // without the triangles of cut tets, their pieces either side, then the cut faces.
  [[nodiscard]] py::tuple surface() const {
    const Eigen::VectorXd& points = m_tissue->current_positions_m();
    std::vector<std::int32_t> triangles;
    triangles.reserve(3 * m_tissue->drawn_triangle_count());
    m_tissue->for_each_drawn_triangle([&](const std::array<int, 3>& t) { triangles.insert(triangles.end(), t.begin(), t.end()); });
    py::array_t<std::int32_t> indices({static_cast<py::ssize_t>(triangles.size() / 3), py::ssize_t{3}});
    std::copy(triangles.begin(), triangles.end(), indices.mutable_data());
    return py::make_tuple(matrix(points.data(), points.size() / 3, 3), indices);
  }
  // The render surface at the current state, cut with the tets: (positions m x 3 [m], normals m x 3,
  // triangles k x 3, the last cap_triangles of them the caps over the cuts); None without one.
  [[nodiscard]] py::object render_surface() const {
    const CutRenderSurface* render = m_tissue->render_surface();
    if (render == nullptr) return py::none();
    const auto rows = [](const std::vector<Eigen::Vector3d>& v) {
      Array out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
      for (std::size_t i = 0; i < v.size(); ++i) std::copy(v[i].data(), v[i].data() + 3, out.mutable_data(i, 0));
      return out;
    };
    const std::vector<std::array<int, 3>>& triangles = render->triangles();
    py::array_t<std::int32_t> indices({static_cast<py::ssize_t>(triangles.size()), py::ssize_t{3}});
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      std::copy(triangles[t].begin(), triangles[t].end(), indices.mutable_data(t, 0));
    }
    py::dict out;
    out["positions_m"] = rows(render->positions_m());
    out["normals"] = rows(render->normals());
    out["triangles"] = indices;
    out["cap_triangles"] = render->cap_triangle_count();
    return out;
  }
  // The mesh ids of the tets a cut went through (ascending).
  [[nodiscard]] py::array_t<std::int32_t> cut_tet_ids() const {
    std::vector<std::int32_t> ids;
    const DeformableBody& body = m_tissue->body();
    for (int t = 0; t < body.mesh().tet_count(); ++t) {
      if (body.cut_tet_index(t) >= 0) ids.push_back(t);
    }
    py::array_t<std::int32_t> out(static_cast<py::ssize_t>(ids.size()));
    std::copy(ids.begin(), ids.end(), out.mutable_data());
    return out;
  }
  // The faces the cuts opened (k x 3, indices into surface()'s points), both sides.
  [[nodiscard]] py::array_t<std::int32_t> cut_faces() const {
    const std::vector<std::array<int, 3>>& faces = m_tissue->drawn_cut_triangles();
    py::array_t<std::int32_t> out({static_cast<py::ssize_t>(faces.size()), py::ssize_t{3}});
    for (std::size_t f = 0; f < faces.size(); ++f) std::copy(faces[f].begin(), faces[f].end(), out.mutable_data(f, 0));
    return out;
  }
  [[nodiscard]] py::dict contact() const {
    const ContactOutput& c = m_tissue->contact();
    py::dict out;
    out["active"] = c.active;
    out["point_m"] = vector3(c.point_m);
    out["normal"] = vector3(c.normal);
    out["force_on_tool_n"] = vector3(c.force_on_tool_n);
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> k = c.stiffness_n_per_m;
    out["stiffness_n_per_m"] = matrix(k.data(), 3, 3);
    out["depth_m"] = c.penetration_depth_m;
    return out;
  }
  [[nodiscard]] py::dict tool_contact() const {
    const ToolContact c = m_tissue->tool_contact();
    py::dict out;
    out["active"] = c.active;
    out["near"] = c.near;
    out["point_m"] = vector3(c.point_m);
    out["normal"] = vector3(c.normal);
    out["force_on_tool_n"] = vector3(c.force_on_tool_n);
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> k = c.stiffness_n_per_m;
    out["stiffness_n_per_m"] = matrix(k.data(), 3, 3);
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> d = c.damping_n_s_per_m;
    out["damping_n_s_per_m"] = matrix(d.data(), 3, 3);
    out["depth_m"] = c.penetration_depth_m;
    return out;
  }
  [[nodiscard]] double contact_spring_stiffness_n_per_m() const { return m_tissue->contact_spring_stiffness_n_per_m(); }
  [[nodiscard]] py::dict tool() const {
    const ToolPose& pose = m_tissue->applied_tool();
    py::dict out;
    out["position_m"] = vector3(m_tissue->applied_tool_position_m());
    out["orientation_wxyz"] = py::make_tuple(pose.orientation.w(), pose.orientation.x(), pose.orientation.y(),
                                             pose.orientation.z());
    out["mode"] = tool_mode_name(pose.mode);
    return out;
  }

  [[nodiscard]] py::bytes save() const {
    TissueSnapshot snapshot;
    m_tissue->save(snapshot);
    const std::vector<std::uint8_t> bytes = serialize_snapshot(snapshot);
    return {reinterpret_cast<const char*>(bytes.data()), bytes.size()};
  }
  void restore(const py::bytes& state) {
    const std::string bytes = state;
    const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
    restore_or_replay(m_tissue, deserialize_snapshot(std::span<const std::uint8_t>(data, bytes.size())));
  }

 private:
  std::unique_ptr<Tissue> m_tissue;
};

// One scenario parameter into the Tissue FMU's stored values, checked as the FMU's set checks it
// (the variable's type, finiteness, an enumeration's items, by name or value).
void write_parameter(fmi3::ValueStore& store, const fmi3::ModelDescription& description, const host::ParameterSetting& p) {
  using fmi3::VariableType;
  const fmi3::VariableInfo* info = description.find(p.name);
  const std::string key = "tissue.parameters." + p.name;
  if (info == nullptr) throw host::ScenarioError(key + ": the Tissue has no such variable");
  if (info->causality != fmi3::Causality::parameter) throw host::ScenarioError(key + ": not a parameter");
  const auto* number = std::get_if<double>(&p.value);
  const auto* integer = std::get_if<std::int64_t>(&p.value);
  const auto* flag = std::get_if<bool>(&p.value);
  const auto* text = std::get_if<std::string>(&p.value);
  const auto* numbers = std::get_if<std::vector<double>>(&p.value);
  try {
    if (info->type == VariableType::float64 && numbers != nullptr) {
      store.write<double>(*info, *numbers);
    } else if (info->type == VariableType::float64 && (number != nullptr || integer != nullptr)) {
      const double value = number != nullptr ? *number : static_cast<double>(*integer);
      store.write<double>(*info, std::span<const double>(&value, 1));
    } else if (info->type == VariableType::int32 && integer != nullptr) {
      if (*integer < INT32_MIN || *integer > INT32_MAX) throw host::ScenarioError(key + ": out of the Int32 range");
      const auto value = static_cast<std::int32_t>(*integer);
      store.write<std::int32_t>(*info, std::span<const std::int32_t>(&value, 1));
    } else if (info->type == VariableType::boolean && flag != nullptr) {
      const bool value = *flag;
      store.write<bool>(*info, std::span<const bool>(&value, 1));
    } else if (info->type == VariableType::string && text != nullptr) {
      const char* value = text->c_str();
      store.write<const char*>(*info, std::span<const char* const>(&value, 1));
    } else if (info->type == VariableType::enumeration && (integer != nullptr || text != nullptr)) {
      std::int64_t item = integer != nullptr ? *integer : -1;
      if (text != nullptr) {
        const fmi3::EnumerationType* type = description.find_enumeration(info->declared_type);
        const auto found = std::find_if(type->items.begin(), type->items.end(),
                                        [&](const fmi3::EnumerationItem& i) { return i.name == *text; });
        if (found == type->items.end()) {
          throw host::ScenarioError(key + ": \"" + *text + "\" is not an item of " + std::string(info->declared_type));
        }
        item = found->value;
      }
      store.write<std::int64_t>(*info, std::span<const std::int64_t>(&item, 1));
    } else {
      throw host::ScenarioError(key + ": the value does not fit the variable's type " +
                                std::string(fmi3::to_string(info->type)));
    }
  } catch (const fmi3::VariableError& error) {
    throw host::ScenarioError(key + ": " + error.what());
  }
}

// A tissue-host scenario: its tissue as the Tissue FMU would build it from the scenario's
// parameters, and its scripted hand's path.
class PyScenario {
 public:
  explicit PyScenario(const std::string& file)
      : m_scenario(host::load_scenario(file)), m_values(tissue_fmu::tissue_model_description()) {
    if (!m_scenario.tissue_fmu.empty()) {
      throw host::ScenarioError(file + ": tissue.fmu names another FMU; only the built-in Tissue's parameters are known here");
    }
    m_values.set_starts();
    for (const host::ParameterSetting& p : m_scenario.tissue_parameters) {
      write_parameter(m_values, tissue_fmu::tissue_model_description(), p);
    }
    (void)tissue_fmu::tissue_settings(m_values, nullptr);  // the core's range checks, now rather than later
  }

  [[nodiscard]] PyTissue tissue() {
    PyTissue made(tissue_fmu::make_tissue(m_values, m_scenario.file.parent_path().string()));
    if (!m_rest_box) {
      std::array<double, 3> lower{1e300, 1e300, 1e300}, upper{-1e300, -1e300, -1e300};
      for (const Eigen::Vector3d& x : made.core().body().mesh().rest_positions_m) {
        for (std::size_t a = 0; a < 3; ++a) {
          lower[a] = std::min(lower[a], x[static_cast<Eigen::Index>(a)]);
          upper[a] = std::max(upper[a], x[static_cast<Eigen::Index>(a)]);
        }
      }
      m_rest_box = {lower, upper};
      m_device = std::make_unique<host::ScriptedDevice>(host::placed_waypoints(m_scenario.device, lower, upper));
    }
    return made;
  }

  // The scripted hand at time t: (position_m, orientation_wxyz, mode), as set_tool takes them.
  [[nodiscard]] py::tuple tool_at(double time_s) {
    const host::DeviceKind kind = m_scenario.device.kind;
    if (kind != host::DeviceKind::scripted && kind != host::DeviceKind::hand) {
      throw host::ScenarioError("tool_at: the scenario's device is not scripted waypoints");
    }
    if (!m_device) (void)tissue();  // the waypoints need the rest box
    const host::DevicePose pose = m_device->read(time_s);
    return py::make_tuple(vector3(to_vector3(pose.position_m)),
                          py::make_tuple(pose.orientation_wxyz[0], pose.orientation_wxyz[1], pose.orientation_wxyz[2],
                                         pose.orientation_wxyz[3]),
                          tool_mode_name(pose.mode));
  }

  [[nodiscard]] const host::Scenario& scenario() const { return m_scenario; }
  [[nodiscard]] py::dict tissue_parameters() const {
    py::dict out;
    for (const host::ParameterSetting& p : m_scenario.tissue_parameters) {
      std::visit([&](const auto& v) { out[py::str(p.name)] = py::cast(v); }, p.value);
    }
    return out;
  }

 private:
  host::Scenario m_scenario;
  fmi3::ValueStore m_values;
  std::optional<std::pair<std::array<double, 3>, std::array<double, 3>>> m_rest_box;
  std::unique_ptr<host::ScriptedDevice> m_device;
};

}  // namespace
}  // namespace tissue::python

PYBIND11_MODULE(tissue, m) {
  using namespace tissue;
  using tissue::python::PyTissue;
  m.doc() = "Real-time deformable tissue: co-rotational FEM, XFEM cutting, probe contact (SI units)";
  py::register_exception<ParameterError>(m, "ParameterError", PyExc_ValueError);
  py::register_exception<IntegrationError>(m, "IntegrationError", PyExc_RuntimeError);
  py::register_exception<StateError>(m, "StateError", PyExc_RuntimeError);
  py::register_exception<host::ScenarioError>(m, "ScenarioError", PyExc_ValueError);
  py::register_exception<fmi3::VariableError>(m, "VariableError", PyExc_ValueError);

  static const std::string tissue_constructor_doc = python::tissue_doc();
  py::class_<PyTissue>(m, "Tissue")
      .def(py::init([](const py::args& args, const py::kwargs& keywords) {
             if (!args.empty()) throw py::type_error("Tissue() takes keyword arguments only");
             return PyTissue::from_keywords(keywords);
           }),
           tissue_constructor_doc.c_str())
      .def("set_tool", &PyTissue::set_tool, py::arg("position_m"),
           py::arg("orientation_wxyz") = std::array<double, 4>{1.0, 0.0, 0.0, 0.0}, py::arg("mode") = "probe",
           "The tool pose for the next step: position [m], unit quaternion (w, x, y, z; the tool's axis is its "
           "+z), mode 'none', 'probe' or 'scalpel'")
      .def("step", &PyTissue::step, py::arg("steps") = 1, "Steps the tissue; the last step's report")
      .def_property_readonly("time_s", &PyTissue::time_s)
      .def_property_readonly("vertex_count", &PyTissue::vertex_count)
      .def_property_readonly("tet_count", &PyTissue::tet_count)
      .def_property_readonly("regions", &PyTissue::regions,
                             "The mesh's regions: {name: (young_modulus_pa, poisson_ratio, density_kg_per_m3)}")
      .def_property_readonly("dof_count", &PyTissue::dof_count)
      .def_property_readonly("parked_rows", &PyTissue::parked_rows,
                             "Block rows (3 unknowns each) of parts cut free that fell out of the operating field "
                             "(field_margin_fraction) and left the dynamics")
      .def_property_readonly("cut_tets", &PyTissue::cut_tets)
      .def_property_readonly("enriched_vertices", &PyTissue::enriched_vertices)
      .def_property_readonly("kinetic_energy_j", &PyTissue::kinetic_energy_j)
      .def_property_readonly("elastic_energy_j", &PyTissue::elastic_energy_j)
      .def_property_readonly("positions_m", &PyTissue::positions_m, "Vertex positions (n x 3) [m]")
      .def_property_readonly("rest_positions_m", &PyTissue::rest_positions_m, "Vertex rest positions (n x 3) [m]")
      .def_property_readonly("contact", &PyTissue::contact, "The last step's contact (force on the tool, K_c)")
      .def_property_readonly("tool_contact", &PyTissue::tool_contact,
                             "What a haptic loop renders after the last step, as the Tissue FMU's contact outputs: "
                             "in contact or near the surface (near_surface_margin_m), the point in the tool "
                             "position's terms (a ball probe's centre), K_c and the damping D_c = beta K_c")
      .def_property_readonly("contact_spring_stiffness_n_per_m", &PyTissue::contact_spring_stiffness_n_per_m)
      .def_property_readonly("tool", &PyTissue::tool, "The pose the last step applied")
      .def("surface", &PyTissue::surface, "The drawn surface: (points (m x 3) [m], triangles (k x 3))")
      .def("render_surface", &PyTissue::render_surface,
           "The render surface cut with the tets: a dict of positions_m, normals, triangles, cap_triangles; None "
           "without one")
      .def_property_readonly("cut_tet_ids", &PyTissue::cut_tet_ids, "Mesh ids of the tets a cut went through")
      .def("cut_faces", &PyTissue::cut_faces, "The faces the cuts opened (k x 3, into surface()'s points)")
      .def("save", &PyTissue::save, "The state as bytes (what FMI's serialized FMU state holds)")
      .def("restore", &PyTissue::restore, py::arg("state"), "Restores a state save() gave, cuts and all")
      .def(
          "quasi_static_poke",
          [](const PyTissue& t, const std::array<double, 3>& target_m) {
            return python::quasi_static_poke(t.core(), target_m);
          },
          py::arg("target_m"),
          "The uncut body's static equilibrium (gravity included) with the surface point straight below target_m "
          "pushed there, frictionless: {converged, force_on_tool_n, normal, stiffness_n_per_m}");

  python::bind_haptic_loop(m).def(
      "set_sample",
      [](python::PyHapticLoop& loop, const PyTissue& t) { loop.set_sample(python::tissue_sample(t.core())); },
      py::arg("tissue"), "The tissue's sample after its last step (what the Tissue FMU sends the HapticLoop FMU)");

  using tissue::python::PyScenario;
  py::class_<PyScenario>(m, "Scenario")
      .def(py::init<const std::string&>(), py::arg("file"),
           "A tissue-host scenario file (TOML, host/README.md): its tissue parameters are checked as the Tissue FMU "
           "checks them")
      .def("tissue", &PyScenario::tissue,
           "A new Tissue as the scenario's Tissue FMU builds it (mesh, material, integrator, contact, ...)")
      .def("tool_at", &PyScenario::tool_at, py::arg("time_s"),
           "The scripted hand at time_s: (position_m, orientation_wxyz, mode), for Tissue.set_tool")
      .def_property_readonly("name", [](const PyScenario& s) { return s.scenario().name; })
      .def_property_readonly("description", [](const PyScenario& s) { return s.scenario().description; })
      .def_property_readonly("duration_s", [](const PyScenario& s) { return s.scenario().duration_s; })
      .def_property_readonly("tissue_step_s", [](const PyScenario& s) { return s.scenario().tissue_step_s; },
                             "The communication step (tissue-host steps the tissue once per slot)")
      .def_property_readonly("haptic_period_s", [](const PyScenario& s) { return s.scenario().haptic_period_s; })
      .def_property_readonly("tissue_parameters", &PyScenario::tissue_parameters,
                             "The Tissue FMU parameters the scenario sets, by name");
}
