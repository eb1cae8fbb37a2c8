// Overhead of the FMI layer (issue 4): one 1 ms step of the default frog called on the core's Tissue
// directly against fmi3DoStep through the packaged Tissue.fmu (host/importer), the same step with
// the inputs and outputs a haptic host exchanges every step, and the cost of reading the full
// surface-mesh arrays. Both sides run the core with the settings the FMU builds from its parameters'
// start values and start from the same state (the same warm-up steps); main() checks that the two
// warmed-up states agree bitwise before anything is timed. Counters report the DOFs.
#include "core/fixed_region.hpp"
#include "core/tissue.hpp"
#include "fmi3/value_store.hpp"
#include "importer/fmu3.hpp"
#include "importer/fmu3_instance.hpp"
#include "resources/default_mesh.hpp"
#include "tissue_fmu/tissue_model.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace tissue {
namespace {

constexpr double STEP_S = 1e-3;           // the FMU's default stepSize: one internal step per doStep
constexpr int WARM_UP_STEPS = 500;        // 0.5 s of simulated time before timing, on both sides
constexpr std::uint64_t CAPACITY = 8192;  // surface.vertexCapacity and surface.triangleCapacity start values

/// The core's settings as the FMU builds them from the start values of its parameters (the one
/// mapping, tissue_fmu/tissue_model.hpp, over the one table of starts).
TissueSettings fmu_default_settings(const TetMesh& mesh) {
  const fmi3::ValueStore starts(tissue_fmu::tissue_model_description());
  TissueSettings s = tissue_fmu::tissue_settings(starts, &mesh);
  if (s.step_size_s != STEP_S) std::exit(1);  // the benchmark times one internal step per doStep
  return s;
}

/// The frog on the core, tool in mode none, after the warm-up.
std::unique_ptr<Tissue> warmed_core() {
  TetMesh mesh = load_default_mesh();
  TissueSettings settings = fmu_default_settings(mesh);
  auto tissue = std::make_unique<Tissue>(std::move(mesh), std::move(settings));
  tissue->set_tool(ToolPose{});
  for (int n = 0; n < WARM_UP_STEPS; ++n) tissue->step();
  return tissue;
}

const host::Fmu3& tissue_fmu() {
  static const host::Fmu3 fmu(TISSUE_FMU_PATH);
  return fmu;
}

/// The value reference of `name`, checked against the one the benchmark was written for.
fmi3ValueReference value_reference(std::string_view name, fmi3ValueReference expected) {
  const fmi3ValueReference vr = tissue_fmu().description().variable(name).value_reference;
  if (vr != expected) {
    std::fprintf(stderr, "bench_fmu: %.*s has value reference %u in the description, expected %u\n",
                 static_cast<int>(name.size()), name.data(), vr, expected);
    std::exit(1);
  }
  return vr;
}

// Looked up once; the thin calls below take them as they are.
struct ValueReferences {
  fmi3ValueReference tool_position = value_reference("tool.position", 30);
  fmi3ValueReference tool_mode = value_reference("tool.mode", 32);
  fmi3ValueReference contact_active = value_reference("contact.active", 40);
  fmi3ValueReference contact_force = value_reference("contact.force", 43);
  fmi3ValueReference contact_stiffness = value_reference("contact.stiffness", 44);
  fmi3ValueReference vertex_count = value_reference("surface.vertexCount", 50);
  fmi3ValueReference triangle_count = value_reference("surface.triangleCount", 51);
  fmi3ValueReference vertex_positions = value_reference("surface.vertexPositions", 53);
  fmi3ValueReference triangles = value_reference("surface.triangles", 54);
  fmi3ValueReference dofs = value_reference("dofs", 62);
};

const ValueReferences& vrs() {
  static const ValueReferences refs;
  return refs;
}

/// One FMU instance with every parameter at its start value (tool in mode none), in step mode
/// after the warm-up. Steps are counted so that the communication point is exact.
class FmuSession {
 public:
  FmuSession() : m_instance(tissue_fmu(), "bench", false) {
    m_ok = m_instance.enter_initialization_mode(std::nullopt, 0.0, std::nullopt) == fmi3OK &&
           m_instance.exit_initialization_mode() == fmi3OK;
    for (int n = 0; m_ok && n < WARM_UP_STEPS; ++n) m_ok = step() == fmi3OK;
  }
  [[nodiscard]] bool ok() const { return m_ok; }
  host::Fmu3Instance& fmu() { return m_instance; }
  fmi3Status step() {
    const fmi3Status status = m_instance.do_step(static_cast<double>(m_steps) * STEP_S, STEP_S).status;
    ++m_steps;
    return status;
  }
  std::uint64_t uint64(fmi3ValueReference vr) {
    std::array<fmi3UInt64, 1> value{};
    m_instance.get_uint64(std::span(&vr, 1), value);
    return value[0];
  }

 private:
  host::Fmu3Instance m_instance;
  long m_steps = 0;
  bool m_ok = false;
};

void BM_CoreStep(benchmark::State& state) {
  std::unique_ptr<Tissue> tissue = warmed_core();
  double iterations = 0.0;
  for (auto _ : state) {
    const TissueStepReport report = tissue->step();
    iterations += report.dynamics.solve.iterations;
    benchmark::DoNotOptimize(report);
  }
  state.counters["dofs"] = tissue->body().dof_count();
  state.counters["pcg_iterations"] = iterations / static_cast<double>(state.iterations());
}
BENCHMARK(BM_CoreStep)->Unit(benchmark::kMicrosecond);

void BM_FmuDoStep(benchmark::State& state) {
  FmuSession session;
  if (!session.ok()) state.SkipWithError("the FMU session did not start");
  for (auto _ : state) {
    if (session.step() != fmi3OK) {
      state.SkipWithError("fmi3DoStep did not return fmi3OK");
      break;
    }
  }
  state.counters["dofs"] = static_cast<double>(session.uint64(vrs().dofs));
}
BENCHMARK(BM_FmuDoStep)->Unit(benchmark::kMicrosecond);

// What a haptic host exchanges every step: the tool in, the contact force, flag and K_c out. The
// tool stays in mode none (away from the frog), so the physics is that of BM_FmuDoStep and the
// difference is the cost of the exchange.
void BM_FmuDoStepWithIo(benchmark::State& state) {
  FmuSession session;
  if (!session.ok()) state.SkipWithError("the FMU session did not start");
  host::Fmu3Instance& fmu = session.fmu();
  const ValueReferences& r = vrs();
  const std::array<fmi3Float64, 3> position{0.0, 0.0, 1.0};
  const std::array<fmi3Int64, 1> mode{0};
  std::array<fmi3Float64, 3> force{};
  std::array<fmi3Float64, 9> stiffness{};
  std::array<fmi3Boolean, 1> active{};
  for (auto _ : state) {
    fmi3Status status = fmu.set_float64(std::span(&r.tool_position, 1), position);
    status = std::max(status, fmu.set_int64(std::span(&r.tool_mode, 1), mode));
    status = std::max(status, session.step());
    status = std::max(status, fmu.get_float64(std::span(&r.contact_force, 1), force));
    status = std::max(status, fmu.get_boolean(std::span(&r.contact_active, 1), active));
    status = std::max(status, fmu.get_float64(std::span(&r.contact_stiffness, 1), stiffness));
    benchmark::DoNotOptimize(force.data());
    benchmark::DoNotOptimize(stiffness.data());
    benchmark::DoNotOptimize(active.data());
    if (status != fmi3OK) {
      state.SkipWithError("a call did not return fmi3OK");
      break;
    }
  }
  state.counters["dofs"] = static_cast<double>(session.uint64(r.dofs));
}
BENCHMARK(BM_FmuDoStepWithIo)->Unit(benchmark::kMicrosecond);

// The mesh output: the full surface.vertexPositions (capacity x 3 Float64) and surface.triangles
// (capacity x 3 UInt32) arrays, as a renderer reads them; no step in between.
void BM_FmuSurfaceOutput(benchmark::State& state) {
  FmuSession session;
  if (!session.ok()) state.SkipWithError("the FMU session did not start");
  host::Fmu3Instance& fmu = session.fmu();
  const ValueReferences& r = vrs();
  std::vector<fmi3Float64> positions(3 * CAPACITY);
  std::vector<fmi3UInt32> triangles(3 * CAPACITY);
  for (auto _ : state) {
    fmi3Status status = fmu.get_float64(std::span(&r.vertex_positions, 1), positions);
    status = std::max(status, fmu.get_uint32(std::span(&r.triangles, 1), triangles));
    benchmark::DoNotOptimize(positions.data());
    benchmark::DoNotOptimize(triangles.data());
    if (status != fmi3OK) {
      state.SkipWithError("a get did not return fmi3OK");
      break;
    }
  }
  state.counters["dofs"] = static_cast<double>(session.uint64(r.dofs));
  state.counters["surface_vertices"] = static_cast<double>(session.uint64(r.vertex_count));
  state.counters["surface_triangles"] = static_cast<double>(session.uint64(r.triangle_count));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(3 * CAPACITY * (sizeof(fmi3Float64) + sizeof(fmi3UInt32))));
}
BENCHMARK(BM_FmuSurfaceOutput)->Unit(benchmark::kMicrosecond);

/// The core and the FMU must time the same physics: after the same warm-up their vertex positions
/// must agree bitwise (same mesh, settings and steps). Returns false, with a message, otherwise.
bool same_state_on_both_sides() {
  const std::unique_ptr<Tissue> core = warmed_core();
  FmuSession session;
  if (!session.ok()) {
    std::fprintf(stderr, "bench_fmu: the FMU session did not start:\n%s\n", session.fmu().log_text().c_str());
    return false;
  }
  std::vector<fmi3Float64> positions(3 * CAPACITY);
  session.fmu().get_float64(std::span(&vrs().vertex_positions, 1), positions);
  const Eigen::VectorXd& expected = core->current_positions_m();
  const auto n = static_cast<std::size_t>(expected.size());
  if (session.uint64(vrs().dofs) != static_cast<std::uint64_t>(core->body().dof_count()) || n > positions.size() ||
      std::memcmp(positions.data(), expected.data(), n * sizeof(double)) != 0) {
    std::fprintf(stderr, "bench_fmu: the FMU's state after %d steps differs from the core's\n", WARM_UP_STEPS);
    return false;
  }
  return true;
}

}  // namespace
}  // namespace tissue

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  if (!tissue::same_state_on_both_sides()) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
