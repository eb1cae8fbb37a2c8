// Issue 42, item 3: the effective contact stiffness K_c at organ scale. The body as the palpation
// holds it (its bottom quarter fixed), its static K at rest, the contact point on the top triangle.
// Per mesh (Arg 0: meshes/liver_coarse.veg, 6136 tets; 1: meshes/liver_tumour.veg, 51 871 tets):
// * BM_ContactStiffnessFactorization/mesh/ordering: one numeric refactorization as
//   EffectiveContactStiffness makes it (supernodal from 3000 rows), ordering 0 AMD, 1 METIS;
//   ordering 2 is the layout and ordering before (automatic: AMD, simplicial unless dense, and the
//   simplicial copy a BLAS-free solve needed).
// * BM_ContactStiffnessCondensation/mesh/method: K_c from that factor, method 0 by the forward
//   solves over the elimination tree's reach (CholmodFactor::lower_solve), 1 by three full solves
//   (what the condensation did before).
// Run: build/release/tests/bench/bench_contact_stiffness --benchmark_repetitions=5
//      --benchmark_report_aggregates_only=true
#include "core/contact/contact_stiffness.hpp"
#include "core/fixed_region.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "core/solve/cholmod_factor.hpp"

#include <benchmark/benchmark.h>

#include <optional>
#include <string>

namespace tissue {
namespace {

struct HeldOrgan {
  explicit HeldOrgan(int which)
      : body(make_body(which)), surface(extract_surface(body.mesh())) {
    Eigen::VectorXd internal_force;
    body.evaluate(Eigen::VectorXd::Zero(body.dof_count()), internal_force, /*update_tangent=*/true);
    int top = 0;
    for (size_t t = 0; t < surface.triangles.size(); ++t) {
      if (body.mesh().rest_positions_m[static_cast<size_t>(surface.triangles[t][0])].z() >
          body.mesh().rest_positions_m[static_cast<size_t>(surface.triangles[static_cast<size_t>(top)][0])].z()) {
        top = static_cast<int>(t);
      }
    }
    point = contact_interpolation(body.dofs(), surface.triangles[static_cast<size_t>(top)],
                                  Eigen::Vector3d::Constant(1.0 / 3.0));
  }
  static DeformableBody make_body(int which) {
    TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + (which == 0 ? "/liver_coarse.veg" : "/liver_tumour.veg"));
    BodySettings settings;
    settings.fixed_vertices = vertices_at_minimum(mesh, 2, 0.25);
    return DeformableBody(std::move(mesh), settings);
  }
  [[nodiscard]] ShiftedSystem system() { return static_contact_system(body.tangent(), zero_diagonal); }

  DeformableBody body;
  SurfaceMesh surface;
  ContactInterpolation point;
  Eigen::VectorXd zero_diagonal;
};

void BM_ContactStiffnessFactorization(benchmark::State& state) {
  HeldOrgan organ(static_cast<int>(state.range(0)));
  const auto variant = state.range(1);
  const CholmodFactor::Ordering ordering = variant == 1 ? CholmodFactor::Ordering::metis : CholmodFactor::Ordering::amd;
  CholmodFactor factor(variant == 2 ? CholmodFactor::Solves::without_blas : CholmodFactor::Solves::with_factor,
                       variant == 2 ? CholmodFactor::Layout::automatic : CholmodFactor::Layout::quickest_factorization,
                       ordering);
  factor.load(organ.system());
  for (auto _ : state) benchmark::DoNotOptimize(factor.factorize());
  state.counters["dofs"] = organ.body.dof_count();
  state.counters["L_entries"] = factor.factor_entries();
  state.counters["supernodal"] = factor.supernodal() ? 1 : 0;
}
BENCHMARK(BM_ContactStiffnessFactorization)
    ->ArgsProduct({{0, 1}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

void BM_ContactStiffnessCondensation(benchmark::State& state) {
  HeldOrgan organ(static_cast<int>(state.range(0)));
  EffectiveContactStiffness effective;
  effective.factorize(organ.system());
  const bool full_solves = state.range(1) == 1;
  if (full_solves) (void)effective.unit_force_response(organ.point);  // the simplicial copy, made once
  double normal_stiffness = 0.0;
  for (auto _ : state) {
    if (full_solves) {
      const EffectiveContactStiffness::ResponseMatrix& response = effective.unit_force_response(organ.point);
      Eigen::Matrix3d compliance = Eigen::Matrix3d::Zero();
      for (size_t k = 0; k < 3; ++k) {
        if (organ.point.rows[k] >= 0) {
          compliance += organ.point.weights[static_cast<Eigen::Index>(k)] * response.middleRows<3>(3 * organ.point.rows[k]);
        }
      }
      normal_stiffness = compliance.inverse()(2, 2);
    } else {
      const std::optional<Eigen::Matrix3d> stiffness = effective.stiffness_n_per_m(organ.point);
      normal_stiffness = stiffness ? (*stiffness)(2, 2) : -1.0;
    }
    benchmark::DoNotOptimize(normal_stiffness);
  }
  state.counters["dofs"] = organ.body.dof_count();
  state.counters["Kzz_N_per_m"] = normal_stiffness;
}
BENCHMARK(BM_ContactStiffnessCondensation)->ArgsProduct({{0, 1}, {0, 1}})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tissue

BENCHMARK_MAIN();
