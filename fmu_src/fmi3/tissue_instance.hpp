// TissueInstance: one Tissue FMU instance behind the C ABI (fmi3_functions.cpp): the parameters and
// inputs as FMI sets them, the FMI 3.0 co-simulation state machine, the core's Tissue built from the
// parameters, the outputs (contact, surface mesh arrays, counters, energies) and FMU states. Errors
// are C++ exceptions here (InstanceError and the core's); the ABI layer turns them into statuses.
#pragma once

#include "core/tissue.hpp"
#include "fmi3/variables.hpp"

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace tissue::fmi3 {

/// A call the instance refuses (wrong state, unknown variable, bad value): fmi3Error.
class InstanceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// FMI 3.0 co-simulation states (the standard's state machine, without configuration and event modes).
enum class InstanceState { instantiated, initialization, step, terminated };

/// Every parameter of modelDescription/Tissue.xml, with its start value.
struct Parameters {
  std::string mesh = "frog";
  Material material;
  RayleighDamping damping{1.0, 1e-3};
  Eigen::Vector3d gravity_m_per_s2{0.0, 0.0, -9.81};
  int fixed_axis = 2;
  double fixed_fraction = 0.25;
  LinearSolverKind linear_solver = LinearSolverKind::pcg;
  double pcg_tolerance = 1e-3;
  int pcg_max_iterations = 10;
  bool warm_start = false;
  double step_size_s = 1e-3;
  bool contact_enabled = true;
  bool cutting_enabled = true;
  bool mesh_output_enabled = true;
  double probe_radius_m = 0.0;
  double blade_length_m = 0.03;
  double contact_spring_stiffness_n_per_m = 0.0;
  ContactStiffnessModel contact_stiffness_model = ContactStiffnessModel::effective_static;
  int contact_stiffness_refresh_steps = 10;
  double min_volume_fraction = 1e-3;
  std::uint64_t vertex_capacity = 8192;
  std::uint64_t triangle_capacity = 8192;
};

/// Tool inputs as set (position of the tip, or of the ball's centre for a probe of radius > 0).
struct ToolInputs {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector4d orientation_wxyz{1.0, 0.0, 0.0, 0.0};
  std::int64_t mode = 0;
};

/// An FMU state: the core's snapshot plus what the FMU layer keeps.
struct InstanceSnapshot {
  TissueSnapshot tissue;
  ToolInputs inputs;
  std::uint64_t surface_revision = 0;
};

class TissueInstance {
 public:
  using Logger = std::function<void(int status, const char* category, const std::string& message)>;

  /// `resource_path`: the unpacked FMU's resources directory (may be empty).
  TissueInstance(std::string name, std::string resource_path, Logger logger);

  [[nodiscard]] InstanceState state() const { return m_state; }
  [[nodiscard]] const std::string& name() const { return m_name; }

  void enter_initialization_mode(double start_time_s);
  void exit_initialization_mode();
  /// Advances by `step_s` from `current_time_s` (must be the instance's time). Returns false, with
  /// the time of the last completed internal step in `last_successful_time_s`, when a step failed.
  bool do_step(double current_time_s, double step_s, double& last_successful_time_s);
  void terminate();
  void reset();

  void get_float64(std::span<const std::uint32_t> vrs, std::span<double> values);
  void set_float64(std::span<const std::uint32_t> vrs, std::span<const double> values);
  void get_int32(std::span<const std::uint32_t> vrs, std::span<std::int32_t> values);
  void set_int32(std::span<const std::uint32_t> vrs, std::span<const std::int32_t> values);
  void get_int64(std::span<const std::uint32_t> vrs, std::span<std::int64_t> values);
  void set_int64(std::span<const std::uint32_t> vrs, std::span<const std::int64_t> values);
  void get_uint32(std::span<const std::uint32_t> vrs, std::span<std::uint32_t> values);
  void get_uint64(std::span<const std::uint32_t> vrs, std::span<std::uint64_t> values);
  void set_uint64(std::span<const std::uint32_t> vrs, std::span<const std::uint64_t> values);
  void get_boolean(std::span<const std::uint32_t> vrs, std::span<bool> values);
  void set_boolean(std::span<const std::uint32_t> vrs, std::span<const bool> values);
  /// The strings stay valid until the next call on this instance.
  void get_string(std::span<const std::uint32_t> vrs, std::span<const char*> values);
  void set_string(std::span<const std::uint32_t> vrs, std::span<const char* const> values);

  [[nodiscard]] std::unique_ptr<InstanceSnapshot> save() const;
  void restore(const InstanceSnapshot& snapshot);
  [[nodiscard]] std::vector<std::uint8_t> serialize(const InstanceSnapshot& snapshot) const;
  [[nodiscard]] std::unique_ptr<InstanceSnapshot> deserialize(std::span<const std::uint8_t> bytes) const;

  /// The core, once built (initialization mode on); for tests and benchmarks of the layer.
  [[nodiscard]] Tissue* tissue() { return m_tissue.get(); }

 private:
  const VariableInfo& variable(std::uint32_t vr, VariableType type, bool setting) const;
  [[nodiscard]] std::size_t element_count(const VariableInfo& info) const;
  void check_settable(const VariableInfo& info) const;
  void check_gettable() const;
  void changed_parameter(const VariableInfo& info);
  void build();
  void ensure_built();
  [[nodiscard]] TissueSettings settings(const TetMesh& mesh) const;
  [[nodiscard]] ToolPose tool_pose() const;
  void update_surface_counters();
  /// Triangles of the surface output: the mesh's surface and the cut faces.
  [[nodiscard]] std::size_t surface_triangle_count() const;
  void warn(const std::string& message) const;

  std::string m_name;
  std::string m_resource_path;
  Logger m_logger;
  InstanceState m_state = InstanceState::instantiated;
  Parameters m_parameters;
  ToolInputs m_inputs;
  double m_start_time_s = 0.0;
  bool m_dirty = true;  // a parameter changed since the Tissue was built
  TetMesh m_mesh;       // as loaded: a fresh Tissue for a restored state with other cuts
  std::unique_ptr<Tissue> m_tissue;
  std::uint64_t m_surface_revision = 0;
  std::uint64_t m_surface_triangles = 0;  // at the last revision check
  mutable bool m_capacity_warned = false;
  mutable std::vector<std::string> m_string_buffer;
};

}  // namespace tissue::fmi3
