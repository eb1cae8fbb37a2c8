// TissueModel (see tissue_model.hpp).
#include "tissue_fmu/tissue_model.hpp"

#include "core/system/resident_reserve.hpp"
#include "core/tissue_settings_schema.hpp"
#include "core/tissue_snapshot_io.hpp"
#include "resources/default_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

namespace tissue::tissue_fmu {
namespace {

using fmi3::ValueStore;
using fmi3::VariableError;
using fmi3::VariableInfo;

fmi3::ValueReference vr(Vr v) { return static_cast<fmi3::ValueReference>(v); }

// The largest capacity an importer is asked to allocate rows for (a bound on the arrays' size).
constexpr std::uint64_t MAX_CAPACITY = 1ULL << 26U;

struct TissueState final : fmi3::ModelState {
  TissueSnapshot tissue;
  std::uint64_t surface_revision = 0;
  std::uint64_t integrator_iterations = 0;
};

// A setting's value as the store holds it (an enumeration's item number as the item's name).
SettingValue stored_value(const ValueStore& values, const SettingInfo& setting) {
  const fmi3::ValueReference ref = setting.value_reference;
  switch (setting.type) {
    case SettingType::real:
      return values.float64(ref);
    case SettingType::integer:
      return static_cast<std::int64_t>(values.int32(ref));
    case SettingType::boolean:
      return values.boolean(ref);
    case SettingType::vector3: {
      const std::span<const double> v = values.float64_array(ref);
      return std::array<double, 3>{v[0], v[1], v[2]};
    }
    case SettingType::enumeration: {
      const std::int64_t item = values.int64(ref);
      if (item < 1 || static_cast<std::size_t>(item) > setting.items.size()) {
        throw VariableError(std::string(setting.name) + " has no item " + std::to_string(item));
      }
      return std::string(setting.items[static_cast<std::size_t>(item - 1)].name);
    }
    case SettingType::text:
      return values.string(ref);
  }
  return values.string(ref);
}

}  // namespace

TissueParameters tissue_parameters(const ValueStore& values) {
  TissueParameters parameters;
  for (const SettingInfo& setting : TISSUE_SETTINGS) set_value(setting, parameters, stored_value(values, setting));
  return parameters;
}

TissueSettings tissue_settings(const ValueStore& values, const TetMesh* mesh) {
  return resolve_settings(tissue_parameters(values), mesh);
}

ToolPose tool_pose(const ValueStore& values) {
  ToolPose pose;
  const std::span<const double> p = values.float64_array(vr(Vr::tool_position));
  const std::span<const double> q = values.float64_array(vr(Vr::tool_orientation));
  pose.tip_position_m = Eigen::Vector3d(p[0], p[1], p[2]);
  pose.orientation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  pose.mode = static_cast<ToolMode>(values.int64(vr(Vr::tool_mode)));
  return pose;
}

TissueModel::TissueModel(const fmi3::ModelContext& context, const ValueStore& values)
    : m_context(context), m_values(values) {}

void TissueModel::validate_parameters(const ValueStore& values) const {
  (void)tissue_settings(values, nullptr);
  for (const Vr capacity : {Vr::vertex_capacity, Vr::triangle_capacity}) {
    const std::uint64_t rows = values.uint64(vr(capacity));
    if (rows < 1 || rows > MAX_CAPACITY) {
      throw VariableError(std::string(tissue_model_description().find(vr(capacity))->name) +
                          " must be in [1, 2^26], got " + std::to_string(rows));
    }
  }
}

// --- the model ---

namespace {

std::string resolve_path(const std::string& name, const char* what, const std::string& resource_path) {
  std::filesystem::path path(name);
  if (path.is_relative()) {
    if (resource_path.empty()) {
      throw VariableError(std::string(what) + " '" + name + "' is relative, but no resource path was given");
    }
    path = std::filesystem::path(resource_path) / path;
  }
  return path.string();
}

}  // namespace

std::unique_ptr<Tissue> make_tissue(const ValueStore& values, const std::string& resource_path) {
  return make_tissue(tissue_parameters(values), resource_path);
}

std::unique_ptr<Tissue> make_tissue(const TissueParameters& parameters, const std::string& resource_path) {
  const std::string& name = parameters.mesh;
  if (name.empty()) throw VariableError("mesh must be a non-empty name or path");
  TetMesh mesh;
  if (name == DEFAULT_MESH_NAME) {
    mesh = load_default_mesh();
  } else {
    try {
      mesh = load_mesh(resolve_path(name, "mesh", resource_path));
    } catch (const std::exception& error) {
      throw VariableError("mesh '" + name + "' cannot be loaded: " + error.what());
    }
  }
  TissueSettings settings = resolve_settings(parameters, &mesh);
  if (const std::string& render = parameters.render_surface; render != NO_RENDER_SURFACE) {
    try {
      TriangleSurface surface = load_render_surface(
          render == DEFAULT_MESH_NAME ? render : resolve_path(render, "surface.renderSurface", resource_path));
      surface.source_name = "surface.renderSurface " + surface.source_name;  // the embedding's messages name both
      settings.render_surface = std::make_shared<const TriangleSurface>(std::move(surface));
    } catch (const std::exception& error) {
      throw VariableError("surface.renderSurface '" + render + "' cannot be loaded: " + error.what());
    }
  }
  return std::make_unique<Tissue>(std::move(mesh), std::move(settings));
}

void TissueModel::build() {
  settle();
  m_encoded_embedding.reset();
  const TissueParameters parameters = tissue_parameters(m_values);
  m_tissue = make_tissue(parameters, m_context.resource_path);
  m_tissue->set_tool(tool_pose(m_values));
  reserve_render_outputs();
  m_dirty = false;
  m_integrator_iterations = 0;
  start_surface_revision(0);
  m_capacity_warned = false;
}

void TissueModel::reserve_render_outputs() {
  const CutRenderSurface* render = m_tissue->render_surface();
  if (render == nullptr) return;
  const size_t points = render->point_room(), triangles = render->triangle_room();
  reserve_resident(m_embedding.triangles, 3 * triangles);
  reserve_resident(m_embedding.point_nodes, 4 * points);
  reserve_resident(m_embedding.point_weights, 4 * points);
  reserve_resident(m_drawn.triangles, 3 * triangles);
  reserve_resident(m_drawn.positions_m, 3 * points);
  // The encoded embedding: its arrays and a header well under a kilobyte.
  const size_t embedding_bytes =
      1024 + 4 * sizeof(std::uint32_t) * points + 4 * sizeof(double) * points + 3 * sizeof(std::uint32_t) * triangles;
  reserve_resident(m_embedding_bytes, embedding_bytes);
  reserve_resident(m_mesh_bytes, 1024 + 3 * sizeof(double) * points + 3 * sizeof(std::uint32_t) * triangles);
}

namespace {

// A render surface's triangles as the surface ports carry them, three corners after another.
void flat_triangles(const CutRenderSurface& render, std::vector<std::uint32_t>& out) {
  out.clear();
  out.reserve(3 * render.triangles().size());
  for (const auto& triangle : render.triangles()) {
    for (const int v : triangle) out.push_back(static_cast<std::uint32_t>(v));
  }
}

}  // namespace

const ports::SurfaceMesh& TissueModel::drawn_mesh() {
  ensure_built();
  if (m_drawn_current) return m_drawn;
  const Tissue& tissue = *m_tissue;
  m_drawn.positions_m.clear();
  m_drawn.triangles.clear();
  if (const CutRenderSurface* render = tissue.render_surface()) {
    for (const Eigen::Vector3d& x : render->positions_m()) m_drawn.positions_m.insert(m_drawn.positions_m.end(), x.data(), x.data() + 3);
    flat_triangles(*render, m_drawn.triangles);
    m_drawn.cut_triangle_count = static_cast<std::uint64_t>(render->cap_triangle_count());
  } else {
    // The triangles first: making them may add points (current_positions_m() has them after).
    tissue.for_each_drawn_triangle([&](const std::array<int, 3>& triangle) {
      for (const int v : triangle) m_drawn.triangles.push_back(static_cast<std::uint32_t>(v));
    });
    m_drawn.cut_triangle_count = tissue.drawn_cut_triangles().size();
    const Eigen::VectorXd& x = tissue.current_positions_m();
    m_drawn.positions_m.assign(x.data(), x.data() + x.size());
  }
  m_drawn_current = true;
  return m_drawn;
}

void TissueModel::drawn_embedding(ports::SurfaceEmbedding& embedding) {
  ensure_built();
  embedding.revision = surface_revision();
  if (const CutRenderSurface* render = m_tissue->render_surface()) {
    // From the render surface itself, not through the drawn mesh (whose points it would copy).
    flat_triangles(*render, embedding.triangles);
    embedding.cut_triangle_count = static_cast<std::uint64_t>(render->cap_triangle_count());
    const std::size_t points = render->positions_m().size();
    embedding.point_nodes.resize(4 * points);
    embedding.point_weights.resize(4 * points);
    embedding.node_count = static_cast<std::uint64_t>(render->node_count());
    for (std::size_t i = 0; i < points; ++i) {
      const Eigen::Vector4d w = render->point_weights(static_cast<int>(i));
      for (std::size_t k = 0; k < 4; ++k) {
        embedding.point_nodes[4 * i + k] = static_cast<std::uint32_t>(render->point_nodes()[i][k]);
        embedding.point_weights[4 * i + k] = w(static_cast<Eigen::Index>(k));
      }
    }
    return;
  }
  // The tet skin: each point is its own node.
  const ports::SurfaceMesh& drawn = drawn_mesh();
  embedding.triangles = drawn.triangles;
  embedding.cut_triangle_count = drawn.cut_triangle_count;
  const std::size_t points = drawn.positions_m.size() / 3;
  embedding.point_nodes.resize(4 * points);
  embedding.point_weights.resize(4 * points);
  embedding.node_count = points;
  for (std::size_t i = 0; i < points; ++i) {
    for (std::size_t k = 0; k < 4; ++k) {
      embedding.point_nodes[4 * i + k] = static_cast<std::uint32_t>(i);
      embedding.point_weights[4 * i + k] = k == 0 ? 1.0 : 0.0;
    }
  }
}

void TissueModel::drawn_nodes(ports::SurfaceNodes& nodes) {
  ensure_built();
  nodes.revision = surface_revision();
  if (const CutRenderSurface* render = m_tissue->render_surface()) {
    // The nodes alone: not the drawn mesh's points and triangles (the organ's 82k every frame; the host maps them).
    nodes.positions_m.clear();
    for (const Eigen::Vector3d& x : render->node_positions_m()) nodes.positions_m.insert(nodes.positions_m.end(), x.data(), x.data() + 3);
    return;
  }
  nodes.positions_m = drawn_mesh().positions_m;
}

bool TissueModel::embedding_encoded(bool mesh_output) const {
  return m_encoded_embedding && m_encoded_embedding->revision == surface_revision() &&
         m_encoded_embedding->mesh_output == mesh_output;
}

const std::vector<std::uint8_t>& TissueModel::embedding_bytes(bool mesh_output) {
  if (embedding_encoded(mesh_output)) return m_embedding_bytes;
  m_encoded_embedding.reset();
  if (mesh_output) {
    drawn_embedding(m_embedding);
  } else {
    m_embedding = ports::SurfaceEmbedding{};
    m_embedding.revision = surface_revision();
  }
  ports::encode(m_embedding, m_embedding_bytes);
  m_encoded_embedding = EncodedEmbedding{surface_revision(), mesh_output};
  return m_embedding_bytes;
}

void TissueModel::prepare_surface() {
  const bool mesh_output = m_values.boolean(vr(Vr::mesh_output_enabled));
  if (!m_values.boolean(vr(Vr::surface_prepare)) || !mesh_output || embedding_encoded(true)) return;
  (void)surface_revision();  // here, not in the job (surface_revision's rule)
  if (!m_tissue->has_render_surface()) (void)m_tissue->current_positions_m();  // the tet skin's job reads them
  // The job reads the tissue (const) and writes the render surface's and the embedding's members, which every
  // other call leaves alone until settle(); noexcept: a failure leaves the bytes stale, so the read that follows
  // computes them again and reports it. (Written when first read, the surface's positions are written above.)
  m_surface_work.start([this] {
    try {
      (void)embedding_bytes(true);
    } catch (...) {
      m_encoded_embedding.reset();
    }
  });
}

void TissueModel::ensure_built() {
  if (m_dirty || !m_tissue) build();
}

std::size_t TissueModel::revision_triangles() const {
  return m_tissue->has_render_surface() ? 0 : m_tissue->drawn_triangle_count();
}

void TissueModel::start_surface_revision(std::uint64_t revision) {
  m_surface_revision = revision;
  m_surface_revision_stale = false;
  m_surface_triangles = revision_triangles();
  m_surface_cut_tets = m_tissue->body().cut_tets().size();
  m_drawn_current = false;
  m_blade_depth_m.reset();  // a state built or restored: found when read
}

void TissueModel::surface_moved() {
  m_drawn_current = false;
  m_surface_revision_stale = true;
}

std::uint64_t TissueModel::surface_revision() const {
  if (!m_surface_revision_stale) return m_surface_revision;
  m_surface_revision_stale = false;
  const std::size_t triangles = revision_triangles();
  const std::size_t cut_tets = m_tissue->body().cut_tets().size();
  if (triangles != m_surface_triangles || cut_tets != m_surface_cut_tets) {
    ++m_surface_revision;
    m_surface_triangles = triangles;
    m_surface_cut_tets = cut_tets;
  }
  return m_surface_revision;
}

void TissueModel::warn_if_arrays_truncate() {
  settle();
  if (!m_values.boolean(vr(Vr::mesh_output_enabled)) || m_capacity_warned) return;
  const ports::SurfaceMesh& drawn = drawn_mesh();
  const std::uint64_t vertices = drawn.positions_m.size() / 3;
  const std::uint64_t vertex_capacity = m_values.uint64(vr(Vr::vertex_capacity));
  const std::uint64_t triangle_capacity = m_values.uint64(vr(Vr::triangle_capacity));
  if (vertices > vertex_capacity || drawn.triangles.size() / 3 > triangle_capacity) {
    m_capacity_warned = true;
    m_context.log(fmi3::LogLevel::warning,
                  "the surface (" + std::to_string(vertices) + " vertices, " + std::to_string(drawn.triangles.size() / 3) +
                      " triangles) outgrew surface.vertexCapacity / surface.triangleCapacity (" +
                      std::to_string(vertex_capacity) + ", " + std::to_string(triangle_capacity) +
                      "): the arrays hold the first ones only; surface.mesh holds the whole surface (or instantiate "
                      "with larger capacities)");
  }
}

void TissueModel::enter_initialization_mode(double start_time_s) { m_start_time_s = start_time_s; }

void TissueModel::exit_initialization_mode() { ensure_built(); }

fmi3::StepOutcome TissueModel::do_step(double current_time_s, double step_s) {
  settle();
  m_blade_depth_m.reset();
  Tissue& tissue = *m_tissue;
  const double now = m_start_time_s + tissue.time_s();
  const long count = fmi3::whole_internal_steps(now, current_time_s, step_s, tissue.settings().step_size_s);
  tissue.set_tool(tool_pose(m_values));  // the inputs' one check (Tissue::set_tool), where they are used
  const std::size_t cuts_before = tissue.body().cut_tets().size();
  const bool contact_before = tissue.contact().active;
  const auto log_events = [&] {
    const std::size_t cuts = tissue.body().cut_tets().size();
    if (cuts != cuts_before) {
      m_context.log(fmi3::LogLevel::event, "t = " + std::to_string(m_start_time_s + tissue.time_s()) +
                                               " s: " + std::to_string(cuts - cuts_before) + " tets cut (" +
                                               std::to_string(cuts) + " in all)");
    }
    if (tissue.contact().active != contact_before) {
      m_context.log(fmi3::LogLevel::event, std::string("contact ") + (tissue.contact().active ? "started" : "ended") +
                                               " at t = " + std::to_string(m_start_time_s + tissue.time_s()) + " s");
    }
  };
  // A step that fails leaves the time at the last internal step that succeeded (Tissue::step is
  // all or nothing for the time and the state): doStep discards with that time, never half advanced.
  for (long n = 0; n < count; ++n) {
    try {
      const TissueStepReport report = tissue.step();
      m_integrator_iterations += static_cast<std::uint64_t>(report.dynamics.newton_iterations) +
                                 static_cast<std::uint64_t>(report.dynamics.linear_iterations);
    } catch (const std::exception& error) {
      surface_moved();
      log_events();
      m_context.log(fmi3::LogLevel::warning, std::string("doStep: an internal step failed: ") + error.what());
      return {false, m_start_time_s + tissue.time_s()};
    }
  }
  surface_moved();
  log_events();
  m_blade_depth_m = tissue.blade_depth_m();
  prepare_surface();
  return {true, m_start_time_s + tissue.time_s()};
}

void TissueModel::reset() {
  settle();
  m_encoded_embedding.reset();
  m_start_time_s = 0.0;
  m_tissue.reset();
  m_dirty = true;
  m_surface_revision = 0;
  m_surface_revision_stale = false;
}

// --- outputs ---

void TissueModel::get_float64(const VariableInfo& info, std::span<double> out) {
  ensure_built();
  Tissue& tissue = *m_tissue;
  const auto put3 = [&](const Eigen::Vector3d& v) {
    for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(k)] = v(k);
  };
  const auto put33 = [&](const Eigen::Matrix3d& m) {
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) out[static_cast<std::size_t>(3 * r + c)] = m(r, c);
    }
  };
  switch (static_cast<Vr>(info.vr)) {
    case Vr::time:
    case Vr::sample_time:
      out[0] = m_start_time_s + tissue.time_s();
      return;
    case Vr::contact_point:
      put3(tissue.tool_contact().point_m);
      return;
    case Vr::contact_normal:
      put3(tissue.tool_contact().normal);
      return;
    case Vr::contact_force:
      put3(tissue.tool_contact().force_on_tool_n);
      return;
    case Vr::contact_stiffness:
      put33(tissue.tool_contact().stiffness_n_per_m);
      return;
    case Vr::contact_damping:
      put33(tissue.tool_contact().damping_n_s_per_m);
      return;
    case Vr::contact_depth:
      out[0] = tissue.tool_contact().penetration_depth_m;
      return;
    case Vr::kinetic_energy:
      out[0] = tissue.kinetic_energy_j();
      return;
    case Vr::elastic_energy:
      settle();  // not const: the body's scratch
      out[0] = tissue.elastic_energy_j();
      return;
    case Vr::blade_depth:  // no wait for the job after a doStep: found there before it started
      if (!m_blade_depth_m) settle();
      out[0] = m_blade_depth_m ? *m_blade_depth_m : *(m_blade_depth_m = tissue.blade_depth_m());
      return;
    case Vr::tool_applied_position:
      put3(tissue.applied_tool_position_m());
      return;
    case Vr::vertex_positions: {
      settle();
      std::fill(out.begin(), out.end(), 0.0);
      if (!m_values.boolean(vr(Vr::mesh_output_enabled))) return;
      warn_if_arrays_truncate();
      const std::vector<double>& x = drawn_mesh().positions_m;
      std::copy_n(x.begin(), std::min(x.size(), out.size()), out.begin());
      return;
    }
    default:
      Model::get_float64(info, out);
  }
}

void TissueModel::get_uint32(const VariableInfo& info, std::span<std::uint32_t> out) {
  if (static_cast<Vr>(info.vr) != Vr::triangles) Model::get_uint32(info, out);
  ensure_built();
  settle();
  std::fill(out.begin(), out.end(), 0U);
  if (!m_values.boolean(vr(Vr::mesh_output_enabled))) return;
  warn_if_arrays_truncate();
  // Whole rows only.
  const std::vector<std::uint32_t>& triangles = drawn_mesh().triangles;
  std::copy_n(triangles.begin(), std::min(triangles.size(), out.size() / 3 * 3), out.begin());
}

void TissueModel::get_uint64(const VariableInfo& info, std::span<std::uint64_t> out) {
  ensure_built();
  const Tissue& tissue = *m_tissue;
  const bool mesh_out = m_values.boolean(vr(Vr::mesh_output_enabled));
  // The drawn surface is brought up to date only for the variables that count it: the cut counters are cheap.
  const Vr which = static_cast<Vr>(info.vr);
  if (which == Vr::vertex_count || which == Vr::triangle_count || which == Vr::cut_triangle_count) settle();
  switch (which) {
    case Vr::vertex_count:
      warn_if_arrays_truncate();
      out[0] = mesh_out ? std::min<std::uint64_t>(drawn_mesh().positions_m.size() / 3, m_values.uint64(vr(Vr::vertex_capacity))) : 0;
      return;
    case Vr::triangle_count:
      warn_if_arrays_truncate();
      out[0] = mesh_out ? std::min<std::uint64_t>(drawn_mesh().triangles.size() / 3, m_values.uint64(vr(Vr::triangle_capacity))) : 0;
      return;
    case Vr::surface_revision:
      if (m_surface_revision_stale) settle();  // (none runs then: surface_revision's rule)
      out[0] = surface_revision();
      return;
    case Vr::cut_triangle_count:
      out[0] = mesh_out ? std::min<std::uint64_t>(drawn_mesh().cut_triangle_count, drawn_mesh().triangles.size() / 3) : 0;
      return;
    case Vr::cut_tets:
      out[0] = static_cast<std::uint64_t>(tissue.body().cut_tet_count());
      return;
    case Vr::enriched_vertices:
      out[0] = static_cast<std::uint64_t>(tissue.body().enriched_dof_count());
      return;
    case Vr::dofs:
      out[0] = static_cast<std::uint64_t>(tissue.body().dof_count());
      return;
    case Vr::integrator_iterations:
      out[0] = m_integrator_iterations;
      return;
    default:
      Model::get_uint64(info, out);
  }
}

void TissueModel::get_boolean(const VariableInfo& info, std::span<bool> out) {
  const auto which = static_cast<Vr>(info.vr);
  if (which == Vr::surface_preparing) {  // no settle(): it says whether a read would wait
    out[0] = m_surface_work.busy();
    return;
  }
  if (which != Vr::contact_active && which != Vr::contact_near) Model::get_boolean(info, out);
  ensure_built();
  const ToolContact contact = m_tissue->tool_contact();
  out[0] = which == Vr::contact_active ? contact.active : contact.near;
}

std::span<const std::uint8_t> TissueModel::get_binary(const VariableInfo& info) {
  ensure_built();
  settle();
  const bool mesh_out = m_values.boolean(vr(Vr::mesh_output_enabled));
  switch (static_cast<Vr>(info.vr)) {
    case Vr::surface_mesh: {
      static const ports::SurfaceMesh NONE;
      ports::encode(mesh_out ? drawn_mesh() : NONE, m_mesh_bytes);
      return m_mesh_bytes;
    }
    case Vr::surface_embedding:
      return embedding_bytes(mesh_out);
    case Vr::surface_nodes:
      if (mesh_out) {
        drawn_nodes(m_nodes);
      } else {
        m_nodes = ports::SurfaceNodes{};
        m_nodes.revision = surface_revision();
      }
      ports::encode(m_nodes, m_nodes_bytes);
      return m_nodes_bytes;
    default:
      return Model::get_binary(info);
  }
}

// --- FMU states ---

std::unique_ptr<fmi3::ModelState> TissueModel::save() const {
  settle();
  if (!m_tissue || m_dirty) throw VariableError("get FMU state: there is no model state before the model is built");
  auto state = std::make_unique<TissueState>();
  m_tissue->save(state->tissue);
  state->surface_revision = surface_revision();
  state->integrator_iterations = m_integrator_iterations;
  return state;
}

void TissueModel::restore(const fmi3::ModelState& model_state) {
  const auto* state = dynamic_cast<const TissueState*>(&model_state);
  if (state == nullptr) throw VariableError("set FMU state: not a Tissue FMU state");
  ensure_built();
  settle();
  m_encoded_embedding.reset();  // the restored revision may number another surface
  try {
    restore_or_replay(m_tissue, state->tissue);
  } catch (const StateError& error) {
    throw VariableError(std::string("set FMU state: ") + error.what());
  }
  m_integrator_iterations = state->integrator_iterations;
  start_surface_revision(state->surface_revision);
}

void TissueModel::serialize(const fmi3::ModelState& model_state, serial::ByteWriter& writer) const {
  const auto& state = dynamic_cast<const TissueState&>(model_state);
  writer.put_bytes(serialize_snapshot(state.tissue));
  writer.put(state.surface_revision);
  writer.put(state.integrator_iterations);
}

std::unique_ptr<fmi3::ModelState> TissueModel::deserialize(serial::ByteReader& reader) const {
  auto state = std::make_unique<TissueState>();
  state->tissue = deserialize_snapshot(reader.get_bytes());
  reader.get(state->surface_revision);
  reader.get(state->integrator_iterations);
  return state;
}

}  // namespace tissue::tissue_fmu
