// TissueInstance (see tissue_instance.hpp).
#include "fmi3/tissue_instance.hpp"

#include "core/fixed_region.hpp"
#include "core/tissue_snapshot_io.hpp"
#include "resources/default_mesh.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>

namespace tissue::fmi3 {
namespace {

constexpr int STATUS_WARNING = 1;  // fmi3Warning: the logger's status of a warning

std::string vr_text(std::uint32_t vr) { return "value reference " + std::to_string(vr); }

double positive(double value, const char* what) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    throw InstanceError(std::string(what) + " must be finite and > 0, got " + std::to_string(value));
  }
  return value;
}

double at_least_zero(double value, const char* what) {
  if (!(value >= 0.0) || !std::isfinite(value)) {
    throw InstanceError(std::string(what) + " must be finite and >= 0, got " + std::to_string(value));
  }
  return value;
}

}  // namespace

TissueInstance::TissueInstance(std::string name, std::string resource_path, Logger logger)
    : m_name(std::move(name)), m_resource_path(std::move(resource_path)), m_logger(std::move(logger)) {}

void TissueInstance::warn(const std::string& message) const {
  if (m_logger) m_logger(STATUS_WARNING, "logStatusWarning", message);
}

// --- variables ---

const VariableInfo& TissueInstance::variable(std::uint32_t vr, VariableType type, bool setting) const {
  const VariableInfo* info = find_variable(vr);
  if (info == nullptr) throw InstanceError("unknown " + vr_text(vr));
  if (info->type != type) {
    throw InstanceError(std::string(info->name) + " (" + vr_text(vr) + ") is of type " +
                        std::string(to_string(info->type)) + ", not " + std::string(to_string(type)));
  }
  if (setting) check_settable(*info);
  return *info;
}

std::size_t TissueInstance::element_count(const VariableInfo& info) const {
  std::size_t count = 1;
  for (int k = 0; k < info.rank; ++k) {
    const Dimension& d = info.dimensions[static_cast<size_t>(k)];
    if (d.size_vr < 0) {
      count *= d.size;
    } else if (static_cast<Vr>(d.size_vr) == Vr::vertex_capacity) {
      count *= m_parameters.vertex_capacity;
    } else {
      count *= m_parameters.triangle_capacity;
    }
  }
  return count;
}

void TissueInstance::check_settable(const VariableInfo& info) const {
  switch (info.causality) {
    case Causality::structural_parameter:
    case Causality::parameter:
      if (m_state != InstanceState::instantiated && m_state != InstanceState::initialization) {
        throw InstanceError("parameter " + std::string(info.name) +
                            " can be set only before initialization ends (it is fixed)");
      }
      if (info.causality == Causality::structural_parameter && m_state != InstanceState::instantiated) {
        throw InstanceError("structural parameter " + std::string(info.name) + " can be set only when instantiated");
      }
      return;
    case Causality::input:
      if (m_state == InstanceState::terminated) throw InstanceError("inputs cannot be set after termination");
      return;
    case Causality::independent:
    case Causality::output:
      throw InstanceError(std::string(info.name) + " is an " + std::string(to_string(info.causality)) +
                          " and cannot be set");
  }
}

void TissueInstance::check_gettable() const {
  if (m_state == InstanceState::instantiated) {
    throw InstanceError("values can be read from initialization mode on (enter initialization mode first)");
  }
}

void TissueInstance::changed_parameter(const VariableInfo& info) {
  if (info.causality == Causality::parameter || info.causality == Causality::structural_parameter) m_dirty = true;
}

void TissueInstance::get_float64(std::span<const std::uint32_t> vrs, std::span<double> values) {
  check_gettable();
  std::size_t at = 0;
  for (const std::uint32_t vr : vrs) {
    const VariableInfo& info = variable(vr, VariableType::float64, false);
    const std::size_t n = element_count(info);
    if (at + n > values.size()) throw InstanceError("too few values for " + std::string(info.name));
    std::span<double> out = values.subspan(at, n);
    at += n;
    const Parameters& p = m_parameters;
    const auto put3 = [&](const Eigen::Vector3d& v) {
      for (int k = 0; k < 3; ++k) out[static_cast<size_t>(k)] = v(k);
    };
    // Parameters and inputs read back as set; outputs need the built model.
    switch (info.vr) {
      case Vr::young_modulus:
        out[0] = p.material.young_modulus_pa;
        continue;
      case Vr::poisson_ratio:
        out[0] = p.material.poisson_ratio;
        continue;
      case Vr::density:
        out[0] = p.material.density_kg_per_m3;
        continue;
      case Vr::damping_alpha:
        out[0] = p.damping.mass_damping_per_s;
        continue;
      case Vr::damping_beta:
        out[0] = p.damping.stiffness_damping_s;
        continue;
      case Vr::gravity:
        put3(p.gravity_m_per_s2);
        continue;
      case Vr::fixed_fraction:
        out[0] = p.fixed_fraction;
        continue;
      case Vr::pcg_tolerance:
        out[0] = p.pcg_tolerance;
        continue;
      case Vr::step_size:
        out[0] = p.step_size_s;
        continue;
      case Vr::probe_radius:
        out[0] = p.probe_radius_m;
        continue;
      case Vr::blade_length:
        out[0] = p.blade_length_m;
        continue;
      case Vr::contact_spring_stiffness:
        out[0] = p.contact_spring_stiffness_n_per_m;
        continue;
      case Vr::min_volume_fraction:
        out[0] = p.min_volume_fraction;
        continue;
      case Vr::tool_position:
        put3(m_inputs.position_m);
        continue;
      case Vr::tool_orientation:
        for (int k = 0; k < 4; ++k) out[static_cast<size_t>(k)] = m_inputs.orientation_wxyz(k);
        continue;
      default:
        break;
    }
    ensure_built();
    Tissue& tissue = *m_tissue;
    const ContactOutput& contact = tissue.contact();
    switch (info.vr) {
      case Vr::time:
        out[0] = m_start_time_s + tissue.time_s();
        break;
      case Vr::contact_point:
        put3(contact.point_m);
        break;
      case Vr::contact_normal:
        put3(contact.normal);
        break;
      case Vr::contact_force:
        put3(contact.force_on_tool_n);
        break;
      case Vr::contact_stiffness:
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) out[static_cast<size_t>(3 * r + c)] = contact.stiffness_n_per_m(r, c);
        }
        break;
      case Vr::contact_depth:
        out[0] = contact.penetration_depth_m;
        break;
      case Vr::kinetic_energy:
        out[0] = tissue.kinetic_energy_j();
        break;
      case Vr::elastic_energy:
        out[0] = tissue.elastic_energy_j();
        break;
      case Vr::vertex_positions: {
        std::fill(out.begin(), out.end(), 0.0);
        if (!m_parameters.mesh_output_enabled) break;
        const Eigen::VectorXd& x = tissue.current_positions_m();
        const std::size_t count = std::min<std::size_t>(static_cast<std::size_t>(x.size()), out.size());
        std::copy(x.data(), x.data() + count, out.begin());
        break;
      }
      default:
        throw InstanceError("no Float64 value for " + std::string(info.name));
    }
  }
  if (at != values.size())
    throw InstanceError("expected " + std::to_string(at) + " values, got " + std::to_string(values.size()));
}

void TissueInstance::set_float64(std::span<const std::uint32_t> vrs, std::span<const double> values) {
  // Check all first, then apply: a refused call changes nothing.
  Parameters p = m_parameters;
  ToolInputs inputs = m_inputs;
  std::size_t at = 0;
  for (const std::uint32_t vr : vrs) {
    const VariableInfo& info = variable(vr, VariableType::float64, true);
    const std::size_t n = element_count(info);
    if (at + n > values.size()) throw InstanceError("too few values for " + std::string(info.name));
    const std::span<const double> in = values.subspan(at, n);
    at += n;
    for (const double v : in) {
      if (!std::isfinite(v)) throw InstanceError(std::string(info.name) + " must be finite, got " + std::to_string(v));
    }
    switch (info.vr) {
      case Vr::young_modulus:
        p.material.young_modulus_pa = positive(in[0], "material.youngModulus");
        break;
      case Vr::poisson_ratio:
        if (!(in[0] >= 0.0 && in[0] < 0.5)) {
          throw InstanceError("material.poissonRatio must be in [0, 0.5), got " + std::to_string(in[0]));
        }
        p.material.poisson_ratio = in[0];
        break;
      case Vr::density:
        p.material.density_kg_per_m3 = positive(in[0], "material.density");
        break;
      case Vr::damping_alpha:
        p.damping.mass_damping_per_s = at_least_zero(in[0], "damping.alpha");
        break;
      case Vr::damping_beta:
        p.damping.stiffness_damping_s = at_least_zero(in[0], "damping.beta");
        break;
      case Vr::gravity:
        p.gravity_m_per_s2 = Eigen::Vector3d(in[0], in[1], in[2]);
        break;
      case Vr::fixed_fraction:
        if (!(in[0] >= 0.0 && in[0] <= 1.0)) {
          throw InstanceError("fixedRegion.fraction must be in [0, 1], got " + std::to_string(in[0]));
        }
        p.fixed_fraction = in[0];
        break;
      case Vr::pcg_tolerance:
        p.pcg_tolerance = positive(in[0], "integrator.pcgTolerance");
        break;
      case Vr::step_size:
        p.step_size_s = positive(in[0], "stepSize");
        break;
      case Vr::probe_radius:
        p.probe_radius_m = at_least_zero(in[0], "tool.probeRadius");
        break;
      case Vr::blade_length:
        p.blade_length_m = positive(in[0], "tool.bladeLength");
        break;
      case Vr::contact_spring_stiffness:
        p.contact_spring_stiffness_n_per_m = at_least_zero(in[0], "contact.springStiffness");
        break;
      case Vr::min_volume_fraction:
        if (!(in[0] > 0.0 && in[0] < 0.5)) {
          throw InstanceError("cutter.minVolumeFraction must be in (0, 0.5), got " + std::to_string(in[0]));
        }
        p.min_volume_fraction = in[0];
        break;
      case Vr::tool_position:
        inputs.position_m = Eigen::Vector3d(in[0], in[1], in[2]);
        break;
      case Vr::tool_orientation: {
        const Eigen::Vector4d q(in[0], in[1], in[2], in[3]);
        if (!(q.norm() > 1e-12)) throw InstanceError("tool.orientation must be a non-zero quaternion");
        inputs.orientation_wxyz = q;
        break;
      }
      default:
        throw InstanceError("cannot set " + std::string(info.name));
    }
    changed_parameter(info);
  }
  if (at != values.size())
    throw InstanceError("expected " + std::to_string(at) + " values, got " + std::to_string(values.size()));
  m_parameters = p;
  m_inputs = inputs;
}

void TissueInstance::get_int32(std::span<const std::uint32_t> vrs, std::span<std::int32_t> values) {
  check_gettable();
  if (vrs.size() != values.size()) throw InstanceError("Int32: one value per (scalar) variable expected");
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::int32, false);
    switch (info.vr) {
      case Vr::fixed_axis:
        values[k] = m_parameters.fixed_axis;
        break;
      case Vr::pcg_max_iterations:
        values[k] = m_parameters.pcg_max_iterations;
        break;
      case Vr::contact_stiffness_refresh_steps:
        values[k] = m_parameters.contact_stiffness_refresh_steps;
        break;
      default:
        throw InstanceError("no Int32 value for " + std::string(info.name));
    }
  }
}

void TissueInstance::set_int32(std::span<const std::uint32_t> vrs, std::span<const std::int32_t> values) {
  if (vrs.size() != values.size()) throw InstanceError("Int32: one value per (scalar) variable expected");
  Parameters p = m_parameters;
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::int32, true);
    const std::int32_t v = values[k];
    switch (info.vr) {
      case Vr::fixed_axis:
        if (v < -1 || v > 2) throw InstanceError("fixedRegion.axis must be -1, 0, 1 or 2, got " + std::to_string(v));
        p.fixed_axis = v;
        break;
      case Vr::pcg_max_iterations:
        if (v < 1) throw InstanceError("integrator.pcgMaxIterations must be >= 1, got " + std::to_string(v));
        p.pcg_max_iterations = v;
        break;
      case Vr::contact_stiffness_refresh_steps:
        if (v < 1) throw InstanceError("contact.stiffnessRefreshSteps must be >= 1, got " + std::to_string(v));
        p.contact_stiffness_refresh_steps = v;
        break;
      default:
        throw InstanceError("cannot set " + std::string(info.name));
    }
    changed_parameter(info);
  }
  m_parameters = p;
}

void TissueInstance::get_int64(std::span<const std::uint32_t> vrs, std::span<std::int64_t> values) {
  check_gettable();
  if (vrs.size() != values.size()) throw InstanceError("Int64: one value per (scalar) variable expected");
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::enumeration, false);
    switch (info.vr) {
      case Vr::linear_solver:
        values[k] = m_parameters.linear_solver == LinearSolverKind::pcg ? 1 : 2;
        break;
      case Vr::contact_stiffness_model:
        values[k] = m_parameters.contact_stiffness_model == ContactStiffnessModel::effective_static ? 1 : 2;
        break;
      case Vr::tool_mode:
        values[k] = m_inputs.mode;
        break;
      default:
        throw InstanceError("no enumeration value for " + std::string(info.name));
    }
  }
}

void TissueInstance::set_int64(std::span<const std::uint32_t> vrs, std::span<const std::int64_t> values) {
  if (vrs.size() != values.size()) throw InstanceError("Int64: one value per (scalar) variable expected");
  Parameters p = m_parameters;
  ToolInputs inputs = m_inputs;
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::enumeration, true);
    const std::int64_t v = values[k];
    switch (info.vr) {
      case Vr::linear_solver:
        if (v != 1 && v != 2) throw InstanceError("integrator.linearSolver must be 1 (pcg) or 2 (cholmod)");
        p.linear_solver = v == 1 ? LinearSolverKind::pcg : LinearSolverKind::cholmod;
        break;
      case Vr::contact_stiffness_model:
        if (v != 1 && v != 2) {
          throw InstanceError("contact.stiffnessModel must be 1 (effectiveStatic) or 2 (elementLocal)");
        }
        p.contact_stiffness_model =
            v == 1 ? ContactStiffnessModel::effective_static : ContactStiffnessModel::element_local;
        break;
      case Vr::tool_mode:
        if (v < 0 || v > 2)
          throw InstanceError("tool.mode must be 0 (none), 1 (probe) or 2 (scalpel), got " + std::to_string(v));
        inputs.mode = v;
        break;
      default:
        throw InstanceError("cannot set " + std::string(info.name));
    }
    changed_parameter(info);
  }
  m_parameters = p;
  m_inputs = inputs;
}

void TissueInstance::get_uint32(std::span<const std::uint32_t> vrs, std::span<std::uint32_t> values) {
  check_gettable();
  std::size_t at = 0;
  for (const std::uint32_t vr : vrs) {
    const VariableInfo& info = variable(vr, VariableType::uint32, false);
    const std::size_t n = element_count(info);
    if (at + n > values.size()) throw InstanceError("too few values for " + std::string(info.name));
    std::span<std::uint32_t> out = values.subspan(at, n);
    at += n;
    ensure_built();
    std::fill(out.begin(), out.end(), 0u);
    if (!m_parameters.mesh_output_enabled) continue;
    // surface.triangles: the mesh's surface, then the cut faces (their corners follow the vertices).
    std::size_t t = 0;
    const auto put = [&](const std::array<int, 3>& triangle) {
      if (3 * t + 3 > out.size()) return;
      for (int c = 0; c < 3; ++c)
        out[3 * t + static_cast<size_t>(c)] = static_cast<std::uint32_t>(triangle[static_cast<size_t>(c)]);
      ++t;
    };
    for (const auto& triangle : m_tissue->surface().triangles) put(triangle);
    for (const auto& triangle : m_tissue->cut_surface().triangles()) put(triangle);
  }
  if (at != values.size())
    throw InstanceError("expected " + std::to_string(at) + " values, got " + std::to_string(values.size()));
}

void TissueInstance::get_uint64(std::span<const std::uint32_t> vrs, std::span<std::uint64_t> values) {
  check_gettable();
  if (vrs.size() != values.size()) throw InstanceError("UInt64: one value per (scalar) variable expected");
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::uint64, false);
    switch (info.vr) {
      case Vr::vertex_capacity:
        values[k] = m_parameters.vertex_capacity;
        continue;
      case Vr::triangle_capacity:
        values[k] = m_parameters.triangle_capacity;
        continue;
      default:
        break;
    }
    ensure_built();
    const Tissue& tissue = *m_tissue;
    const auto vertices = static_cast<std::uint64_t>(tissue.current_positions_m().size() / 3);
    const auto triangles = static_cast<std::uint64_t>(surface_triangle_count());
    const bool out = m_parameters.mesh_output_enabled;
    switch (info.vr) {
      case Vr::vertex_count:
        values[k] = out ? std::min(vertices, m_parameters.vertex_capacity) : 0;
        break;
      case Vr::triangle_count:
        values[k] = out ? std::min(triangles, m_parameters.triangle_capacity) : 0;
        break;
      case Vr::surface_revision:
        values[k] = m_surface_revision;
        break;
      case Vr::cut_tets:
        values[k] = tissue.body().cut_tets().size();
        break;
      case Vr::enriched_vertices:
        values[k] = static_cast<std::uint64_t>(tissue.body().enriched_dof_count());
        break;
      case Vr::dofs:
        values[k] = static_cast<std::uint64_t>(tissue.body().dof_count());
        break;
      default:
        throw InstanceError("no UInt64 value for " + std::string(info.name));
    }
  }
}

void TissueInstance::set_uint64(std::span<const std::uint32_t> vrs, std::span<const std::uint64_t> values) {
  if (vrs.size() != values.size()) throw InstanceError("UInt64: one value per (scalar) variable expected");
  Parameters p = m_parameters;
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::uint64, true);
    // A capacity bounds the arrays an importer allocates: at least 1, at most 2^26 rows.
    if (values[k] < 1 || values[k] > (1ULL << 26)) {
      throw InstanceError(std::string(info.name) + " must be in [1, 2^26], got " + std::to_string(values[k]));
    }
    (info.vr == Vr::vertex_capacity ? p.vertex_capacity : p.triangle_capacity) = values[k];
    changed_parameter(info);
  }
  m_parameters = p;
}

void TissueInstance::get_boolean(std::span<const std::uint32_t> vrs, std::span<bool> values) {
  check_gettable();
  if (vrs.size() != values.size()) throw InstanceError("Boolean: one value per (scalar) variable expected");
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::boolean, false);
    switch (info.vr) {
      case Vr::warm_start:
        values[k] = m_parameters.warm_start;
        break;
      case Vr::contact_enabled:
        values[k] = m_parameters.contact_enabled;
        break;
      case Vr::cutting_enabled:
        values[k] = m_parameters.cutting_enabled;
        break;
      case Vr::mesh_output_enabled:
        values[k] = m_parameters.mesh_output_enabled;
        break;
      case Vr::contact_active:
        ensure_built();
        values[k] = m_tissue->contact().active;
        break;
      default:
        throw InstanceError("no Boolean value for " + std::string(info.name));
    }
  }
}

void TissueInstance::set_boolean(std::span<const std::uint32_t> vrs, std::span<const bool> values) {
  if (vrs.size() != values.size()) throw InstanceError("Boolean: one value per (scalar) variable expected");
  Parameters p = m_parameters;
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const VariableInfo& info = variable(vrs[k], VariableType::boolean, true);
    switch (info.vr) {
      case Vr::warm_start:
        p.warm_start = values[k];
        break;
      case Vr::contact_enabled:
        p.contact_enabled = values[k];
        break;
      case Vr::cutting_enabled:
        p.cutting_enabled = values[k];
        break;
      case Vr::mesh_output_enabled:
        p.mesh_output_enabled = values[k];
        break;
      default:
        throw InstanceError("cannot set " + std::string(info.name));
    }
    changed_parameter(info);
  }
  m_parameters = p;
}

void TissueInstance::get_string(std::span<const std::uint32_t> vrs, std::span<const char*> values) {
  check_gettable();
  if (vrs.size() != values.size()) throw InstanceError("String: one value per (scalar) variable expected");
  m_string_buffer.clear();
  m_string_buffer.reserve(vrs.size());
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    variable(vrs[k], VariableType::string, false);
    m_string_buffer.push_back(m_parameters.mesh);
  }
  for (std::size_t k = 0; k < vrs.size(); ++k) values[k] = m_string_buffer[k].c_str();
}

void TissueInstance::set_string(std::span<const std::uint32_t> vrs, std::span<const char* const> values) {
  if (vrs.size() != values.size()) throw InstanceError("String: one value per (scalar) variable expected");
  std::string mesh = m_parameters.mesh;
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    variable(vrs[k], VariableType::string, true);
    if (values[k] == nullptr || values[k][0] == '\0') throw InstanceError("mesh must be a non-empty name or path");
    mesh = values[k];
  }
  m_parameters.mesh = mesh;
  m_dirty = true;
}

// --- the model ---

TissueSettings TissueInstance::settings(const TetMesh& mesh) const {
  const Parameters& p = m_parameters;
  TissueSettings s;
  s.body.material = p.material;
  s.body.damping = p.damping;
  s.body.gravity_m_per_s2 = p.gravity_m_per_s2;
  if (p.fixed_axis >= 0) s.body.fixed_vertices = vertices_at_minimum(mesh, p.fixed_axis, p.fixed_fraction);
  s.solver.kind = p.linear_solver;
  s.solver.pcg = PcgSolver::Settings{p.pcg_tolerance, p.pcg_max_iterations};
  s.solver.warm_start = p.warm_start;
  s.step_size_s = p.step_size_s;
  s.interaction.contact_enabled = p.contact_enabled;
  s.interaction.cutting_enabled = p.cutting_enabled;
  s.interaction.blade_length_m = p.blade_length_m;
  s.interaction.cutter.min_volume_fraction = p.min_volume_fraction;
  s.interaction.contact_spring_stiffness_n_per_m = p.contact_spring_stiffness_n_per_m;
  s.interaction.contact_stiffness_model = p.contact_stiffness_model;
  s.interaction.contact_stiffness_refresh_steps = p.contact_stiffness_refresh_steps;
  return s;
}

void TissueInstance::build() {
  const std::string& name = m_parameters.mesh;
  TetMesh mesh;
  if (name == DEFAULT_MESH_NAME) {
    mesh = load_default_mesh();
  } else {
    std::filesystem::path path(name);
    if (path.is_relative()) {
      if (m_resource_path.empty())
        throw InstanceError("mesh '" + name + "' is relative, but no resource path was given");
      path = std::filesystem::path(m_resource_path) / path;
    }
    try {
      mesh = load_mesh(path.string());
    } catch (const std::exception& error) {
      throw InstanceError("mesh '" + name + "' cannot be loaded: " + error.what());
    }
  }
  auto tissue = std::make_unique<Tissue>(mesh, settings(mesh));
  m_mesh = std::move(mesh);
  m_tissue = std::move(tissue);
  m_tissue->set_tool(tool_pose());
  m_dirty = false;
  m_surface_revision = 0;
  m_surface_triangles = surface_triangle_count();
  m_capacity_warned = false;
}

void TissueInstance::ensure_built() {
  if (m_dirty || !m_tissue) build();
}

ToolPose TissueInstance::tool_pose() const {
  ToolPose pose;
  const Eigen::Vector4d& q = m_inputs.orientation_wxyz;
  pose.orientation = Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized();
  pose.mode = static_cast<ToolMode>(m_inputs.mode);
  pose.tip_position_m = m_inputs.position_m;
  // A ball-ended probe touches with the pole of its ball along the tool axis (toward the tip).
  if (pose.mode == ToolMode::probe && m_parameters.probe_radius_m > 0.0) {
    pose.tip_position_m -= m_parameters.probe_radius_m * (pose.orientation * Eigen::Vector3d::UnitZ());
  }
  return pose;
}

std::size_t TissueInstance::surface_triangle_count() const {
  return m_tissue->surface().triangles.size() + m_tissue->cut_surface().triangles().size();
}

void TissueInstance::update_surface_counters() {
  const std::size_t triangles = surface_triangle_count();
  if (triangles != m_surface_triangles) {
    ++m_surface_revision;
    m_surface_triangles = triangles;
  }
  if (!m_parameters.mesh_output_enabled || m_capacity_warned) return;
  const auto vertices = static_cast<std::uint64_t>(m_tissue->current_positions_m().size() / 3);
  if (vertices > m_parameters.vertex_capacity || triangles > m_parameters.triangle_capacity) {
    m_capacity_warned = true;
    warn("the surface (" + std::to_string(vertices) + " vertices, " + std::to_string(triangles) +
         " triangles) outgrew surface.vertexCapacity / surface.triangleCapacity (" +
         std::to_string(m_parameters.vertex_capacity) + ", " + std::to_string(m_parameters.triangle_capacity) +
         "): the arrays hold the first ones only; instantiate with larger capacities");
  }
}

// --- the state machine ---

void TissueInstance::enter_initialization_mode(double start_time_s) {
  if (m_state != InstanceState::instantiated) throw InstanceError("enter initialization mode: only when instantiated");
  if (!std::isfinite(start_time_s)) throw InstanceError("start time must be finite");
  m_start_time_s = start_time_s;
  m_state = InstanceState::initialization;
}

void TissueInstance::exit_initialization_mode() {
  if (m_state != InstanceState::initialization)
    throw InstanceError("exit initialization mode: not in initialization mode");
  ensure_built();
  m_state = InstanceState::step;
}

bool TissueInstance::do_step(double current_time_s, double step_s, double& last_successful_time_s) {
  if (m_state != InstanceState::step) throw InstanceError("doStep: only in step mode (after exit initialization mode)");
  Tissue& tissue = *m_tissue;
  const double now = m_start_time_s + tissue.time_s();
  last_successful_time_s = now;
  if (!std::isfinite(current_time_s) || !(step_s > 0.0) || !std::isfinite(step_s)) {
    throw InstanceError("doStep: the communication point must be finite and the step > 0");
  }
  const double h = m_parameters.step_size_s;
  if (std::abs(current_time_s - now) > 1e-9 * std::max({1.0, std::abs(now), h})) {
    throw InstanceError("doStep: the communication point " + std::to_string(current_time_s) +
                        " s is not the instance's time " + std::to_string(now) + " s");
  }
  const double count = std::round(step_s / h);
  if (count < 1.0 || std::abs(count * h - step_s) > 1e-9 * step_s) {
    throw InstanceError("doStep: the communication step " + std::to_string(step_s) +
                        " s is not a whole multiple of stepSize " + std::to_string(h) + " s");
  }
  tissue.set_tool(tool_pose());
  const std::size_t cuts_before = tissue.body().cut_tets().size();
  const bool contact_before = tissue.contact().active;
  const auto log_events = [&] {
    if (!m_logger) return;
    const std::size_t cuts = tissue.body().cut_tets().size();
    if (cuts != cuts_before) {
      m_logger(0, "logEvents",
               "t = " + std::to_string(m_start_time_s + tissue.time_s()) + " s: " + std::to_string(cuts - cuts_before) +
                   " tets cut (" + std::to_string(cuts) + " in all)");
    }
    if (tissue.contact().active != contact_before) {
      m_logger(0, "logEvents",
               std::string("contact ") + (tissue.contact().active ? "started" : "ended") +
                   " at t = " + std::to_string(m_start_time_s + tissue.time_s()) + " s");
    }
  };
  for (long n = 0; n < static_cast<long>(count); ++n) {
    try {
      tissue.step();
    } catch (const IntegrationError& error) {
      update_surface_counters();
      log_events();
      last_successful_time_s = m_start_time_s + tissue.time_s();
      warn(std::string("doStep: an internal step failed: ") + error.what());
      return false;
    }
  }
  update_surface_counters();
  log_events();
  last_successful_time_s = m_start_time_s + tissue.time_s();
  return true;
}

void TissueInstance::terminate() {
  if (m_state != InstanceState::step && m_state != InstanceState::initialization) {
    throw InstanceError("terminate: only in initialization or step mode");
  }
  m_state = InstanceState::terminated;
}

void TissueInstance::reset() {
  m_state = InstanceState::instantiated;
  m_parameters = Parameters{};
  m_inputs = ToolInputs{};
  m_start_time_s = 0.0;
  m_tissue.reset();
  m_dirty = true;
  m_surface_revision = 0;
}

// --- FMU states ---

std::unique_ptr<InstanceSnapshot> TissueInstance::save() const {
  if (!m_tissue || m_dirty || m_state == InstanceState::instantiated) {
    throw InstanceError("get FMU state: there is no model state before initialization");
  }
  auto snapshot = std::make_unique<InstanceSnapshot>();
  m_tissue->save(snapshot->tissue);
  snapshot->inputs = m_inputs;
  snapshot->surface_revision = m_surface_revision;
  return snapshot;
}

void TissueInstance::restore(const InstanceSnapshot& snapshot) {
  if (m_state == InstanceState::instantiated || m_state == InstanceState::terminated) {
    throw InstanceError("set FMU state: only in initialization or step mode");
  }
  ensure_built();
  try {
    if (m_tissue->can_restore(snapshot.tissue)) {
      m_tissue->restore(snapshot.tissue);
    } else {
      // Cuts cannot be undone in place: a fresh Tissue replays the snapshot's.
      auto fresh = std::make_unique<Tissue>(m_mesh, settings(m_mesh));
      fresh->restore(snapshot.tissue);
      m_tissue = std::move(fresh);
    }
  } catch (const StateError& error) {
    throw InstanceError(std::string("set FMU state: ") + error.what());
  }
  m_inputs = snapshot.inputs;
  m_surface_revision = snapshot.surface_revision;
  m_surface_triangles = surface_triangle_count();
}

std::vector<std::uint8_t> TissueInstance::serialize(const InstanceSnapshot& snapshot) const {
  std::vector<std::uint8_t> bytes = serialize_snapshot(snapshot.tissue);
  const auto put = [&](const auto& value) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&value);
    bytes.insert(bytes.end(), p, p + sizeof(value));
  };
  for (int k = 0; k < 3; ++k) put(snapshot.inputs.position_m(k));
  for (int k = 0; k < 4; ++k) put(snapshot.inputs.orientation_wxyz(k));
  put(snapshot.inputs.mode);
  put(snapshot.surface_revision);
  return bytes;
}

std::unique_ptr<InstanceSnapshot> TissueInstance::deserialize(std::span<const std::uint8_t> bytes) const {
  constexpr std::size_t TAIL = 7 * sizeof(double) + sizeof(std::int64_t) + sizeof(std::uint64_t);
  if (bytes.size() < TAIL) throw InstanceError("deserialize FMU state: too few bytes");
  auto snapshot = std::make_unique<InstanceSnapshot>();
  try {
    snapshot->tissue = deserialize_snapshot(bytes.first(bytes.size() - TAIL));
  } catch (const StateError& error) {
    throw InstanceError(std::string("deserialize FMU state: ") + error.what());
  }
  const std::uint8_t* p = bytes.data() + (bytes.size() - TAIL);
  const auto get = [&](auto& value) {
    std::memcpy(&value, p, sizeof(value));
    p += sizeof(value);
  };
  for (int k = 0; k < 3; ++k) get(snapshot->inputs.position_m(k));
  for (int k = 0; k < 4; ++k) get(snapshot->inputs.orientation_wxyz(k));
  get(snapshot->inputs.mode);
  get(snapshot->surface_revision);
  if (snapshot->inputs.mode < 0 || snapshot->inputs.mode > 2 || !snapshot->inputs.position_m.allFinite() ||
      !snapshot->inputs.orientation_wxyz.allFinite()) {
    throw InstanceError("deserialize FMU state: bad tool inputs");
  }
  return snapshot;
}

}  // namespace tissue::fmi3
