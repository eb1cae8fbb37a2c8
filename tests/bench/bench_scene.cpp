// What the scene switches save ("model only what the scene requires", DESIGN section 1): building
// a Tissue on the embedded frog and stepping it with the tool away, with contact and cutting on or
// off. Counters: the bytes allocated while building (global operator new of this executable) and
// the surface BVH's triangles. Arguments: /contact/cutting (1 = on).
#include "core/fixed_region.hpp"
#include "core/tissue.hpp"
#include "resources/default_mesh.hpp"
#include "support/counting_new.hpp"

#include <benchmark/benchmark.h>

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

}  // namespace
}  // namespace tissue

BENCHMARK_MAIN();
