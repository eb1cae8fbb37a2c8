// Tissue: the facade of the core, one specimen in one scene. Owns the body, the integrator and
// the state; this is what the demo, tissue-bench and (issue 4) the FMU layer call.
#pragma once

#include "core/fem/deformable_body.hpp"
#include "core/integrate/integrator.hpp"
#include "core/solve/linear_solver.hpp"

#include <memory>
#include <string_view>

namespace tissue {

enum class LinearSolverKind { pcg, cholmod };

/// Parses "pcg" / "cholmod"; throws ParameterError otherwise.
LinearSolverKind parse_linear_solver_kind(std::string_view name);

struct SolverSettings {
  LinearSolverKind kind = LinearSolverKind::pcg;
  PcgSolver::Settings pcg;
  bool warm_start = false;  ///< PCG starts from the previous step's velocity change (see BackwardEuler)
};

/// Throws ParameterError unless tolerance > 0 (finite) and max_iterations >= 1.
void validate(const SolverSettings& settings);
std::unique_ptr<LinearSolver> make_linear_solver(const SolverSettings& settings);

struct TissueSettings {
  BodySettings body;
  SolverSettings solver;
  double step_size_s = 1e-3;
};

class Tissue {
 public:
  /// Throws ParameterError for invalid settings.
  Tissue(TetMesh mesh, TissueSettings settings);

  /// One backward-Euler step of step_size_s. Throws IntegrationError (state unchanged) on failure.
  StepReport step();

  [[nodiscard]] const DeformableBody& body() const { return m_body; }
  [[nodiscard]] const DynamicState& state() const { return m_state; }
  [[nodiscard]] const TissueSettings& settings() const { return m_settings; }
  [[nodiscard]] double time_s() const { return m_state.time_s; }
  [[nodiscard]] double kinetic_energy_j() const { return m_body.kinetic_energy_j(m_state.velocity_m_per_s); }
  [[nodiscard]] double elastic_energy_j() { return m_body.elastic_energy_j(m_state.displacement_m); }
  /// Positions of all vertices, 3 per vertex [m].
  void vertex_positions(Eigen::VectorXd& positions_m) const { m_body.positions(m_state.displacement_m, positions_m); }

 private:
  TissueSettings m_settings;
  DeformableBody m_body;
  std::unique_ptr<Integrator> m_integrator;
  DynamicState m_state;
};

}  // namespace tissue
