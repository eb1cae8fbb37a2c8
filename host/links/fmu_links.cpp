// TissueLink, HapticLink and apply_parameters (see fmu_links.hpp).
#include "links/fmu_links.hpp"

#include "importer/fmu_error.hpp"

#include <algorithm>
#include <limits>

namespace tissue::host {
namespace {

fmi3ValueReference vr(const Fmu3Instance& instance, std::string_view name) {
  return instance.description().variable(name).value_reference;
}

void expect_ok(fmi3Status status, Fmu3Instance& instance, const std::string& what) {
  if (status == fmi3OK || status == fmi3Warning) return;
  throw FmuError(what + " failed (" + status_name(status) + "): " + instance.log_text());
}

}  // namespace

void apply_parameters(Fmu3Instance& instance, const std::vector<ParameterSetting>& parameters,
                      const std::string& where) {
  for (const ParameterSetting& p : parameters) {
    const std::string key = where + "." + p.name;
    const ModelVariable* variable = instance.description().find_variable(p.name);
    if (variable == nullptr) throw ScenarioError(key + ": the FMU has no variable of this name");
    if (variable->causality != "parameter" && variable->causality != "structuralParameter") {
      throw ScenarioError(key + ": is a " + variable->causality + ", not a parameter");
    }
    const auto* number = std::get_if<double>(&p.value);
    const auto* integer = std::get_if<std::int64_t>(&p.value);
    const auto* flag = std::get_if<bool>(&p.value);
    const auto* text = std::get_if<std::string>(&p.value);
    const auto* numbers = std::get_if<std::vector<double>>(&p.value);
    fmi3Status status = fmi3Error;
    const std::string& type = variable->type;
    if (type == "Float64") {
      if (numbers != nullptr) {
        status = instance.set_float64(p.name, *numbers);
      } else if (number != nullptr || integer != nullptr) {
        status = instance.set_float64(p.name, {number != nullptr ? *number : static_cast<double>(*integer)});
      } else {
        throw ScenarioError(key + ": a Float64 needs a number");
      }
    } else if (type == "Int32" && integer != nullptr) {
      if (*integer < std::numeric_limits<std::int32_t>::min() || *integer > std::numeric_limits<std::int32_t>::max()) {
        throw ScenarioError(key + ": out of the Int32 range");
      }
      status = instance.set_int32(p.name, {static_cast<std::int32_t>(*integer)});
    } else if (type == "UInt64" && integer != nullptr) {
      if (*integer < 0) throw ScenarioError(key + ": must be >= 0");
      status = instance.set_uint64(p.name, {static_cast<std::uint64_t>(*integer)});
    } else if (type == "Boolean" && flag != nullptr) {
      status = instance.set_boolean(p.name, {*flag});
    } else if (type == "String" && text != nullptr) {
      status = instance.set_string(p.name, {*text});
    } else if (type == "Enumeration" && (integer != nullptr || text != nullptr)) {
      std::int64_t item = integer != nullptr ? *integer : -1;
      if (text != nullptr) {
        const auto& types = instance.description().type_definitions();
        const auto type_it = std::find_if(types.begin(), types.end(),
                                          [&](const TypeDefinition& t) { return t.name == variable->declared_type; });
        bool found = false;
        if (type_it != types.end()) {
          for (const EnumerationItem& candidate : type_it->items) {
            if (candidate.name == *text) {
              item = candidate.value;
              found = true;
            }
          }
        }
        if (!found) throw ScenarioError(key + ": \"" + *text + "\" is not an item of " + variable->declared_type);
      }
      status = instance.set_int64(p.name, {item});
    } else {
      throw ScenarioError(key + ": the value does not fit the variable's type " + type);
    }
    if (status != fmi3OK) {
      const std::string log = instance.log_text();
      instance.clear_log();
      throw ScenarioError(key + ": refused by the FMU: " + log);
    }
  }
}

// --- Tissue ---

TissueLink::TissueLink(const Fmu3& fmu, const std::vector<ParameterSetting>& parameters)
    : m_instance(fmu, "tissue", false),
      m_tool_position(vr(m_instance, "tool.position")),
      m_tool_orientation(vr(m_instance, "tool.orientation")),
      m_tool_mode(vr(m_instance, "tool.mode")),
      m_revision(vr(m_instance, "surface.revision")),
      m_embedding_vr(vr(m_instance, "surface.embedding")),
      m_nodes_vr(vr(m_instance, "surface.nodes")),
      m_cut_tets(vr(m_instance, "cutTets")),
      m_enriched(vr(m_instance, "enrichedVertices")) {
  if (const auto* prepare = m_instance.description().find_variable("surface.prepareAfterStep")) {
    m_prepare_vr = prepare->value_reference;
  }
  if (const auto* preparing = m_instance.description().find_variable("surface.preparing")) {
    m_preparing_vr = preparing->value_reference;
  }
  apply_parameters(m_instance, parameters, "tissue.parameters");
  expect_ok(m_instance.enter_initialization_mode(std::nullopt, 0.0, std::nullopt), m_instance,
            "Tissue: enter initialization mode");
  expect_ok(m_instance.exit_initialization_mode(), m_instance, "Tissue: exit initialization mode");
  std::vector<double> blade;
  expect_ok(m_instance.get_float64("tool.bladeLength", blade), m_instance, "Tissue: blade length");
  m_blade_length_m = blade.at(0);
  // The box of the nodes at rest: the tet mesh's vertices whichever surface is drawn (a render
  // surface lies within the tets), so that a scenario's tool path is the same for both.
  SurfaceFrame rest;
  read_surface(rest);
  m_rest_lower.fill(std::numeric_limits<double>::infinity());
  m_rest_upper.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < rest.node_positions_m.size(); ++i) {
    m_rest_lower[i % 3] = std::min(m_rest_lower[i % 3], rest.node_positions_m[i]);
    m_rest_upper[i % 3] = std::max(m_rest_upper[i % 3], rest.node_positions_m[i]);
  }
}

void TissueLink::set_tool(const ToolCommand& tool) {
  const std::array<fmi3ValueReference, 2> vrs{m_tool_position, m_tool_orientation};
  std::array<double, 7> values{};
  std::copy(tool.position_m.begin(), tool.position_m.end(), values.begin());
  std::copy(tool.orientation_wxyz.begin(), tool.orientation_wxyz.end(), values.begin() + 3);
  (void)m_instance.set_float64(vrs, values);
  const std::array<fmi3Int64, 1> mode{tool.mode};
  (void)m_instance.set_int64(std::span<const fmi3ValueReference>(&m_tool_mode, 1), mode);
}

void TissueLink::prepare_surface_after_step(bool prepare) {
  if (!m_prepare_vr || prepare == m_prepare) return;
  const std::array<fmi3Boolean, 1> value{prepare};
  if (m_instance.set_boolean(std::span<const fmi3ValueReference>(&*m_prepare_vr, 1), value) == fmi3OK) m_prepare = prepare;
}

DoStepResult TissueLink::step(double time_s, double step_s) { return m_instance.do_step(time_s, step_s); }

void TissueLink::read_counters(RelaySample& sample) {
  std::array<fmi3UInt64, 2> counters{};
  const std::array<fmi3ValueReference, 2> counter_vrs{m_cut_tets, m_enriched};
  (void)m_instance.get_uint64(counter_vrs, counters);
  sample.cut_tets = counters[0];
  sample.enriched_vertices = counters[1];
}

void TissueLink::reserve(SurfaceFrame& frame) const {
  if (!m_embedding) return;
  frame.positions_m.reserve(2 * 3 * m_embedding->point_count());
  frame.triangles.reserve(2 * m_embedding->triangles.size());
  frame.node_positions_m.reserve(2 * 3 * m_embedding->node_count);
}

std::uint64_t TissueLink::surface_revision() {
  fmi3UInt64 revision = 0;
  (void)m_instance.get_uint64(std::span(&m_revision, 1), std::span(&revision, 1));
  return revision;
}

bool TissueLink::surface_remeshed() { return !embedding_read_at(surface_revision()); }

bool TissueLink::surface_preparing() {
  if (!m_preparing_vr) return false;
  std::array<fmi3Boolean, 1> preparing{false};
  (void)m_instance.get_boolean(std::span<const fmi3ValueReference>(&*m_preparing_vr, 1), preparing);
  return preparing[0];
}

void TissueLink::read_surface(SurfaceFrame& frame) {
  read_surface_unmapped(frame);
  m_mapping.complete(frame);
  if (!m_embedding) m_embedding = frame.embedding;
}

void TissueLink::read_surface_unmapped(SurfaceFrame& frame) {
  const auto binary = [&](fmi3ValueReference which, const char* what) {
    std::size_t size = 0;
    fmi3Binary bytes = nullptr;
    const fmi3Status status = m_instance.get_binary(std::span(&which, 1), std::span(&size, 1), std::span(&bytes, 1));
    if (status != fmi3OK) expect_ok(status, m_instance, std::string("Tissue: ") + what);  // the message only if needed
    if (bytes == nullptr && size > 0) throw FmuError(std::string("Tissue: ") + what + " is a null pointer");
    return std::span<const std::uint8_t>(bytes, size);
  };
  try {
    const std::uint64_t revision = surface_revision();
    if (!embedding_read_at(revision)) {
      m_embedding_bytes = m_embedding_copies.copy(binary(m_embedding_vr, "surface.embedding"));
      m_embedding_revision = revision;
    }
    ports::decode(binary(m_nodes_vr, "surface.nodes"), m_nodes);
  } catch (const ports::SurfaceBinaryError& error) {
    throw FmuError(std::string("Tissue: ") + error.what());
  }
  frame.embedding.reset();
  frame.embedding_bytes = m_embedding_bytes;
  frame.node_revision = m_nodes.revision;
  frame.node_positions_m.assign(m_nodes.positions_m.begin(), m_nodes.positions_m.end());
  frame.positions_m.clear();
  frame.triangles.clear();
  frame.mesh_triangle_count = 0;
}

void SurfaceMapping::complete(SurfaceFrame& frame) {
  if (!frame.embedding_bytes) return;
  try {
    if (frame.embedding_bytes != m_bytes) {
      auto embedding = std::make_shared<ports::SurfaceEmbedding>();
      ports::decode(*frame.embedding_bytes, *embedding);
      m_embedding = std::move(embedding);
      m_bytes = frame.embedding_bytes;
    }
    m_nodes.revision = frame.node_revision;
    m_nodes.positions_m.assign(frame.node_positions_m.begin(), frame.node_positions_m.end());
    ports::map_points(*m_embedding, m_nodes, frame.positions_m);
  } catch (const ports::SurfaceBinaryError& error) {
    throw FmuError(std::string("Tissue: ") + error.what());
  }
  frame.embedding = m_embedding;
  frame.embedding_bytes.reset();
  frame.triangles.assign(m_embedding->triangles.begin(), m_embedding->triangles.end());
  // The cut faces are the last rows; the rest is the skin.
  frame.mesh_triangle_count = frame.triangle_count() - static_cast<std::size_t>(m_embedding->cut_triangle_count);
}

// --- HapticLoop ---

HapticLink::HapticLink(const Fmu3& fmu, const std::vector<ParameterSetting>& parameters)
    : m_instance(fmu, "haptic", false),
      m_device_float{vr(m_instance, "device.position"), vr(m_instance, "device.orientation")},
      m_device_mode(vr(m_instance, "device.toolMode")),
      m_out_float{vr(m_instance, "tool.position"), vr(m_instance, "tool.orientation"), vr(m_instance, "device.force")},
      m_out_energy{vr(m_instance, "passivity.observedEnergy"), vr(m_instance, "passivity.dissipatedEnergy")},
      m_out_mode(vr(m_instance, "tool.mode")),
      m_out_flags{vr(m_instance, "force.clamped"), vr(m_instance, "force.rateLimited"),
                  vr(m_instance, "passivity.acted")} {
  apply_parameters(m_instance, parameters, "haptic.parameters");
  expect_ok(m_instance.enter_initialization_mode(std::nullopt, 0.0, std::nullopt), m_instance,
            "HapticLoop: enter initialization mode");
  expect_ok(m_instance.exit_initialization_mode(), m_instance, "HapticLoop: exit initialization mode");
  std::vector<double> max_force;
  expect_ok(m_instance.get_float64("device.maxForce", max_force), m_instance, "HapticLoop: max force");
  m_max_force_n = max_force.at(0);
  expect_ok(m_instance.get_float64("device.maxForceRate", max_force), m_instance, "HapticLoop: max force rate");
  m_max_force_rate_n_per_s = max_force.at(0);
}

void HapticLink::set_device(const DevicePose& pose) {
  std::array<double, 7> values{};
  std::copy(pose.position_m.begin(), pose.position_m.end(), values.begin());
  std::copy(pose.orientation_wxyz.begin(), pose.orientation_wxyz.end(), values.begin() + 3);
  (void)m_instance.set_float64(m_device_float, values);
  const std::array<fmi3Int64, 1> mode{static_cast<fmi3Int64>(pose.mode)};
  (void)m_instance.set_int64(std::span<const fmi3ValueReference>(&m_device_mode, 1), mode);
}

DoStepResult HapticLink::step(double time_s, double step_s) { return m_instance.do_step(time_s, step_s); }

void HapticLink::read(HapticOutputs& out) {
  std::array<double, 10> values{};
  (void)m_instance.get_float64(m_out_float, values);
  std::copy(values.begin(), values.begin() + 3, out.tool.position_m.begin());
  std::copy(values.begin() + 3, values.begin() + 7, out.tool.orientation_wxyz.begin());
  std::copy(values.begin() + 7, values.end(), out.device_force_n.begin());
  std::array<double, 2> energy{};
  (void)m_instance.get_float64(m_out_energy, energy);
  out.observed_energy_j = energy[0];
  out.dissipated_energy_j = energy[1];
  std::array<fmi3Int64, 1> mode{};
  (void)m_instance.get_int64(std::span<const fmi3ValueReference>(&m_out_mode, 1), mode);
  out.tool.mode = mode[0];
  std::array<fmi3Boolean, 3> flags{};
  (void)m_instance.get_boolean(m_out_flags, flags);
  out.clamped = flags[0];
  out.rate_limited = flags[1];
  out.passivity_acted = flags[2];
}

}  // namespace tissue::host
