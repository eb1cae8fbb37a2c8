// What the scene switches save (docs/DESIGN.md, "One Tissue step": only what the scene requires): building
// a Tissue on the embedded frog and stepping it with the tool away, with contact and cutting on or
// off. Counters: the bytes allocated while building (global operator new of this executable) and
// the surface BVH's triangles. Arguments: /contact/cutting (1 = on).
#include "core/fixed_region.hpp"
#include "core/tissue.hpp"
#include "resources/default_mesh.hpp"
#include "support/counting_new.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

namespace tissue {
namespace {

TissueSettings scene_settings(const TetMesh& mesh, bool contact, bool cutting) {
  TissueSettings settings;
  settings.body.gravity_m_per_s2 = {0.0, 0.0, -9.81};
  settings.body.damping = RayleighDamping{1.0, 1e-3};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 2, 0.25);
  settings.solver.pcg = PcgSolver::Settings{1e-3, 10};
  settings.interaction.contact_enabled = contact;
  settings.interaction.cutting_enabled = cutting;
  return settings;
}

void BM_BuildScene(benchmark::State& state) {
  const TetMesh mesh = load_default_mesh();
  const TissueSettings settings = scene_settings(mesh, state.range(0) != 0, state.range(1) != 0);
  std::size_t bytes = 0;
  int triangles = 0;
  for (auto _ : state) {
    const std::size_t before = g_allocated_bytes.load();
    auto tissue = std::make_unique<Tissue>(mesh, settings);
    bytes = g_allocated_bytes.load() - before;
    triangles = tissue->surface_bvh().triangle_count();
    benchmark::DoNotOptimize(tissue.get());
  }
  state.counters["alloc_MB"] = static_cast<double>(bytes) / 1e6;
  state.counters["bvh_triangles"] = triangles;
}
BENCHMARK(BM_BuildScene)->ArgsProduct({{1, 0}, {1, 0}})->Unit(benchmark::kMillisecond);

void BM_StepScene(benchmark::State& state) {
  const TetMesh mesh = load_default_mesh();
  Tissue tissue(mesh, scene_settings(mesh, state.range(0) != 0, state.range(1) != 0));
  for (int n = 0; n < 50; ++n) tissue.step();  // settle into the sag
  for (auto _ : state) benchmark::DoNotOptimize(tissue.step().total_s);
  state.counters["dofs"] = tissue.body().dof_count();
}
BENCHMARK(BM_StepScene)->ArgsProduct({{1, 0}, {1, 0}})->Unit(benchmark::kMicrosecond);

// What backward Euler's large-turn protections (Newton corrections, energy guard) cost where they
// mostly do not act: a session on the frog, the probe pressed 6 mm into the back over 0.5 s and held
// to 1 s, the tool away, a vertical scalpel drawn across the body from 1.1 s to 2.1 s, then 0.9 s
// of rest; one iteration is the whole session. Arguments: /step in us/protections (1 = the
// defaults, 0 = both off). Counters: ms per step, Newton iterations and guarded steps per session.
void BM_PressAndCutSession(benchmark::State& state) {
  const TetMesh mesh = load_default_mesh();
  TissueSettings settings = scene_settings(mesh, true, true);
  settings.step_size_s = 1e-6 * static_cast<double>(state.range(0));
  settings.interaction.blade_length_m = 0.1;
  if (state.range(1) == 0) {
    settings.integrator.newton.trigger_angle_rad = std::numeric_limits<double>::infinity();
    settings.integrator.newton.energy_guard_angle_rad = std::numeric_limits<double>::infinity();
  }
  Eigen::Vector3d lower = mesh.rest_positions_m[0], upper = lower;
  for (const Eigen::Vector3d& x : mesh.rest_positions_m) {
    lower = lower.cwiseMin(x);
    upper = upper.cwiseMax(x);
  }
  const Eigen::Vector3d centre = 0.5 * (lower + upper);
  const Eigen::Quaterniond upright = Eigen::Quaterniond::Identity();
  const int steps = static_cast<int>(std::lround(3.0 / settings.step_size_s));
  long newton_iterations = 0, guarded_steps = 0;
  double step_seconds = 0.0;
  for (auto _ : state) {
    Tissue tissue(mesh, settings);
    newton_iterations = guarded_steps = 0;
    const auto start = std::chrono::steady_clock::now();
    for (int n = 0; n < steps; ++n) {
      const double t = n * settings.step_size_s;
      ToolPose pose{Eigen::Vector3d(centre.x(), centre.y(), upper.z() + 0.05), upright, ToolMode::none};
      if (t < 1.0) {
        pose = {Eigen::Vector3d(centre.x(), centre.y(), upper.z() + 0.001 - 0.006 * std::min(1.0, t / 0.5)), upright,
                ToolMode::probe};
      } else if (t > 1.1 && t < 2.1) {
        const double y = lower.y() - 0.01 + (t - 1.1) * (upper.y() - lower.y() + 0.02);
        pose = {Eigen::Vector3d(centre.x(), y, lower.z() - 0.01), upright, ToolMode::scalpel};
      }
      tissue.set_tool(pose);
      const TissueStepReport report = tissue.step();
      newton_iterations += report.dynamics.newton_iterations;
      guarded_steps += report.dynamics.energy_guarded ? 1 : 0;
    }
    step_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / steps;
  }
  state.counters["ms_per_step"] = 1e3 * step_seconds;
  state.counters["newton_iterations"] = static_cast<double>(newton_iterations);
  state.counters["guarded_steps"] = static_cast<double>(guarded_steps);
}
BENCHMARK(BM_PressAndCutSession)
    ->ArgsProduct({{1000, 10000}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace
}  // namespace tissue

BENCHMARK_MAIN();
