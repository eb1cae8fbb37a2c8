// Kernels of one backward-Euler step on the embedded frog and on bar_40x8x8: rotation extraction,
// force + tangent assembly, the block matrix-vector product, a 10-iteration PCG solve and a
// CHOLMOD factorization + solve, the two-level preconditioner and its coarse factor. Counters report
// DOFs and non-zeros.
#include "core/collide/surface_bvh.hpp"
#include "core/cut/volume_cutter.hpp"
#include "core/fem/body_parts.hpp"
#include "core/fem/stable_neo_hookean.hpp"
#include "core/fixed_region.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/mesh/topology.hpp"
#include "core/render/cut_render_surface.hpp"
#include "core/render/embedded_surface.hpp"
#include "core/solve/block_cholesky.hpp"
#include "core/solve/half_matrix.hpp"
#include "core/solve/two_level_preconditioner.hpp"
#include "core/system/work_team.hpp"
#include "core/tissue.hpp"
#include "resources/default_mesh.hpp"

#include <Eigen/SparseCholesky>
#include <benchmark/benchmark.h>

#include <functional>
#include <optional>
#include <random>

namespace tissue {
namespace {

TetMesh bench_mesh(int which) {
  if (which == 2) return read_mesh(std::string(TISSUE_MESH_DIR) + "/liver.veg");
  return which == 0 ? load_default_mesh() : read_mesh(std::string(TISSUE_MESH_DIR) + "/bar_40x8x8.veg");
}

struct Fixture {
  explicit Fixture(int which) : body(make_body(which)) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
    displacement = Eigen::VectorXd::NullaryExpr(body.dof_count(), [&] { return jitter(rng); });
    body.evaluate(displacement, forces, true);
  }
  static DeformableBody make_body(int which) {
    TetMesh mesh = bench_mesh(which);
    BodySettings settings;
    settings.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
    return DeformableBody(std::move(mesh), settings);
  }
  void count(benchmark::State& state) const {
    state.counters["dofs"] = body.dof_count();
    state.counters["nonzeros"] = static_cast<double>(body.tangent().nonzeros());
    state.counters["tets"] = body.mesh().tet_count();
  }
  DeformableBody body;
  Eigen::VectorXd displacement, forces;
};

void BM_ForcesOnly(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    f.body.evaluate(f.displacement, f.forces, false);
    benchmark::DoNotOptimize(f.forces.data());
  }
  f.count(state);
}
BENCHMARK(BM_ForcesOnly)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_ForcesAndTangent(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    f.body.evaluate(f.displacement, f.forces, true);
    benchmark::DoNotOptimize(f.forces.data());
  }
  f.count(state);
}
BENCHMARK(BM_ForcesAndTangent)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

// The stable Neo-Hookean kernel alone (issue 25): per tet F, forces and the 12 x 12 tangent with
// (range(1) = 1) or without the per-element PSD projection (a 9 x 9 eigendecomposition), at the same
// positions as BM_ForcesAndTangent, not assembled: what the hyperelastic option costs before any
// assembly, against the whole co-rotational evaluate above.
void BM_StableNeoHookeanKernel(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)));
  const bool project = state.range(1) != 0;
  const TetMesh& mesh = f.body.mesh();
  Eigen::VectorXd positions;
  f.body.positions(f.displacement, positions);
  std::vector<TetRest> rests;
  for (int t = 0; t < mesh.tet_count(); ++t) rests.push_back(precompute_tet(mesh.rest_corners(t)));
  const StableNeoHookean material = stable_neo_hookean(f.body.elasticity().lame()[0]);
  for (auto _ : state) {
    double sum = 0.0;
    for (int t = 0; t < mesh.tet_count(); ++t) {
      TetPositions x;
      for (size_t i = 0; i < 4; ++i) x[i] = positions.segment<3>(3 * mesh.tets[static_cast<size_t>(t)][i]);
      const Eigen::Matrix3d gradient = deformation_gradient(rests[static_cast<size_t>(t)], x);
      sum += neo_hookean_forces(rests[static_cast<size_t>(t)], material, gradient)(0, 0);
      sum += neo_hookean_stiffness(rests[static_cast<size_t>(t)], material, gradient, project)(0, 0);
    }
    benchmark::DoNotOptimize(sum);
  }
  f.count(state);
}
BENCHMARK(BM_StableNeoHookeanKernel)->Args({0, 0})->Args({0, 1})->Unit(benchmark::kMicrosecond);

void BM_BlockMultiply(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)));
  Eigen::VectorXd y(f.body.dof_count());
  for (auto _ : state) {
    f.body.tangent().multiply(f.displacement, y);
    benchmark::DoNotOptimize(y.data());
  }
  f.count(state);
}
BENCHMARK(BM_BlockMultiply)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_HalfMultiply(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)));
  const Eigen::VectorXd diagonal = f.body.mass_kg();
  const ShiftedSystem system{&f.body.tangent(), 1e-4, &diagonal};
  HalfMatrix half(state.range(1) == 1 ? MatrixPrecision::single : MatrixPrecision::double_precision);
  half.assign(system);
  Eigen::VectorXd y(f.body.dof_count());
  for (auto _ : state) {
    half.multiply(f.displacement, y);
    benchmark::DoNotOptimize(y.data());
  }
  f.count(state);
}
BENCHMARK(BM_HalfMultiply)->ArgsProduct({{0, 2}, {0, 1}})->Unit(benchmark::kMicrosecond);

// The warm start's eight products in one pass over the values (HalfMatrix::multiply_columns); the
// time is for all eight (compare eight times BM_HalfMultiply's).
void BM_HalfMultiplyEightColumns(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)));
  const Eigen::VectorXd diagonal = f.body.mass_kg();
  const ShiftedSystem system{&f.body.tangent(), 1e-4, &diagonal};
  HalfMatrix half(state.range(1) == 1 ? MatrixPrecision::single : MatrixPrecision::double_precision);
  half.assign(system);
  Eigen::MatrixXd x(f.body.dof_count(), HalfMatrix::COLUMN_LANES);
  for (int c = 0; c < x.cols(); ++c) x.col(c) = (c + 1.0) * f.displacement;
  RowMajorMatrix y;
  for (auto _ : state) {
    half.multiply_columns(x, y);
    benchmark::DoNotOptimize(y.data());
  }
  f.count(state);
}
BENCHMARK(BM_HalfMultiplyEightColumns)->ArgsProduct({{0, 2}, {0, 1}})->Unit(benchmark::kMicrosecond);

void solve_benchmark(benchmark::State& state, LinearSolver& solver) {
  Fixture f(static_cast<int>(state.range(0)));
  const double h = 0.01;
  const Eigen::VectorXd diagonal = f.body.mass_kg();
  const ShiftedSystem system{&f.body.tangent(), h * h, &diagonal};
  const Eigen::VectorXd rhs = h * (f.body.external_force_n() - f.forces);
  Eigen::VectorXd x(f.body.dof_count());
  for (auto _ : state) {
    x.setZero();
    benchmark::DoNotOptimize(solver.solve(system, rhs, x));
  }
  f.count(state);
}

void BM_Pcg10Iterations(benchmark::State& state) {
  PcgSolver solver({1e-30, 10});
  solve_benchmark(state, solver);
}
BENCHMARK(BM_Pcg10Iterations)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// The two-level preconditioner's set-up (tissue's default real-time solver): Arg 1 = aggregating
// anew and the coarse level (a cut step's), Arg 0 = a coarse refresh over the kept aggregates
// (COARSE_REFRESH_SETUPS setups, one of which refreshes: the steps between cuts, per refresh).
void BM_TwoLevelSetup(benchmark::State& state) {
  Fixture f(static_cast<int>(state.range(0)));
  const double h = 0.01;
  const Eigen::VectorXd diagonal = f.body.mass_kg();
  ShiftedSystem system{&f.body.tangent(), h * h, &diagonal};
  system.block_positions = f.body.block_positions(f.displacement);
  const Eigen::VectorXd inverse_diagonal = Eigen::VectorXd::Ones(f.body.dof_count());
  const bool aggregate = state.range(1) != 0;
  TwoLevelPreconditioner preconditioner;
  preconditioner.setup(system, inverse_diagonal);
  for (auto _ : state) {
    if (aggregate) {
      preconditioner.forget();
      preconditioner.setup(system, inverse_diagonal);
    } else {
      for (int k = 0; k < TwoLevelPreconditioner::COARSE_REFRESH_SETUPS; ++k) preconditioner.setup(system, inverse_diagonal);
    }
    benchmark::DoNotOptimize(preconditioner.coarse_size());
  }
  f.count(state);
  state.counters["coarse"] = preconditioner.coarse_size();
}
BENCHMARK(BM_TwoLevelSetup)->Args({0, 0})->Args({0, 1})->Args({1, 0})->Args({1, 1})->Args({2, 0})->Unit(benchmark::kMicrosecond);

// The two-level preconditioner's coarse factor (BlockCholesky) against Eigen's scalar simplicial
// LDL^T, which it replaced, on a coarse matrix of the organ's size (its own: 159 aggregates, 950
// columns): a 6 x 6 x 5 grid of 180 aggregates of 6 columns, each coupled to its 26 neighbours,
// random values made diagonally dominant. Arg 0: 0 = scalar, 1 = blocks; Arg 1: 0 = factorization, 1 = one
// solve (the pair of triangular solves a CG iteration takes).
struct CoarseGrid {
  std::vector<int> row_begin{0}, row_column, column_begin{0};
  std::vector<BlockCholesky::BlockValues> blocks;
  Eigen::SparseMatrix<double> lower;  // the same matrix, scalar, its lower triangle
  CoarseGrid() {
    constexpr int NX = 6, NY = 6, NZ = 5, B = BlockCholesky::BLOCK;
    const auto id = [](int x, int y, int z) { return x + NX * (y + NY * z); };
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> value(-1.0, 1.0);
    std::vector<Eigen::Triplet<double>> entries;
    const int n = NX * NY * NZ;
    for (int a = 0; a < n; ++a) column_begin.push_back(column_begin.back() + B);
    for (int z = 0; z < NZ; ++z) {
      for (int y = 0; y < NY; ++y) {
        for (int x = 0; x < NX; ++x) {
          const int a = id(x, y, z);
          for (int dz = -1; dz <= 1; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
              for (int dx = -1; dx <= 1; ++dx) {
                const int bx = x + dx, by = y + dy, bz = z + dz;
                if (bx < 0 || by < 0 || bz < 0 || bx >= NX || by >= NY || bz >= NZ) continue;
                const int b = id(bx, by, bz);
                if (b < a) continue;
                row_column.push_back(b);
                BlockCholesky::BlockValues block{};
                for (int i = 0; i < B; ++i) {
                  for (int j = 0; j < B; ++j) {
                    const double v = a == b ? (i == j ? 60.0 : 0.5 * value(rng)) : value(rng);
                    block[static_cast<size_t>(i + B * j)] = v;
                  }
                }
                if (a == b) {  // symmetric
                  for (int i = 0; i < B; ++i) {
                    for (int j = 0; j < i; ++j) block[static_cast<size_t>(j + B * i)] = block[static_cast<size_t>(i + B * j)];
                  }
                }
                for (int i = 0; i < B; ++i) {
                  for (int j = 0; j < B; ++j) {
                    const int r = B * a + i, c = B * b + j;
                    if (r >= c) entries.emplace_back(r, c, block[static_cast<size_t>(i + B * j)]);
                    if (a != b) entries.emplace_back(c, r, block[static_cast<size_t>(i + B * j)]);
                  }
                }
                blocks.push_back(block);
              }
            }
          }
          row_begin.push_back(static_cast<int>(row_column.size()));
        }
      }
    }
    lower.resize(B * n, B * n);
    lower.setFromTriplets(entries.begin(), entries.end());
  }
};

void BM_CoarseCholesky(benchmark::State& state) {
  static const CoarseGrid grid;
  const bool block_factor = state.range(0) == 1;
  const bool solve = state.range(1) == 1;
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(grid.lower.rows());
  Eigen::VectorXd x(b.size());
  if (block_factor) {
    BlockCholesky factor;
    factor.analyze(grid.row_begin, grid.row_column, grid.column_begin);
    if (!factor.factorize(grid.blocks)) state.SkipWithError("not positive definite");
    for (auto _ : state) {
      if (solve) {
        factor.solve(b, x);
      } else {
        benchmark::DoNotOptimize(factor.factorize(grid.blocks));
      }
      benchmark::ClobberMemory();
    }
    state.counters["factor_entries"] = 36.0 * factor.factor_blocks();
  } else {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> factor;
    factor.analyzePattern(grid.lower);
    factor.factorize(grid.lower);
    for (auto _ : state) {
      if (solve) {
        x = factor.solve(b);
      } else {
        factor.factorize(grid.lower);
      }
      benchmark::ClobberMemory();
    }
    state.counters["factor_entries"] = static_cast<double>(factor.matrixL().nestedExpression().nonZeros());
  }
  state.counters["columns"] = static_cast<double>(grid.lower.rows());
}
BENCHMARK(BM_CoarseCholesky)->Args({0, 0})->Args({1, 0})->Args({0, 1})->Args({1, 1})->Unit(benchmark::kMicrosecond);

// What a look for parts out of the field costs after a cut (Tissue, every PARK_CHECK_STEPS steps
// of a cut body; between cuts the parts are kept): the union-find over every element's rows. Arg 0
// frog (2.4k tets), 1 bar_40x8x8, 2 the organ (meshes/liver.veg, 52k tets).
void BM_FindBodyParts(benchmark::State& state) {
  TetMesh mesh = state.range(0) == 2 ? read_mesh(std::string(TISSUE_MESH_DIR) + "/liver.veg")
                                     : bench_mesh(static_cast<int>(state.range(0)));
  BodySettings settings;
  settings.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
  const DeformableBody body(std::move(mesh), settings);
  for (auto _ : state) benchmark::DoNotOptimize(find_body_parts(body).count());
  state.counters["tets"] = body.mesh().tet_count();
}
BENCHMARK(BM_FindBodyParts)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

void BM_CholmodFactorizeAndSolve(benchmark::State& state) {
  CholmodSolver solver;
  solve_benchmark(state, solver);
}
BENCHMARK(BM_CholmodFactorizeAndSolve)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_RotationExtraction(benchmark::State& state) {
  // Warm-started, as in a step: a small rotation and stretch since the last call.
  const Eigen::Matrix3d increment = Eigen::AngleAxisd(1e-3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Eigen::Matrix3d f = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                      Eigen::Vector3d(1.1, 0.95, 1.0).asDiagonal();
  Eigen::Quaterniond warm = Eigen::Quaterniond::Identity();
  for (auto _ : state) {
    f = increment * f;
    benchmark::DoNotOptimize(extract_rotation(f, warm));
  }
}
BENCHMARK(BM_RotationExtraction)->Unit(benchmark::kNanosecond);

// Issue 22: mapping the frog's render surface (meshes/frog_surface.obj, 23240 triangles) onto
// deformed tets: positions and normals of one frame. Target: <= 0.3 ms on one core.
void BM_RenderSurfaceMap(benchmark::State& state) {
  const TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  EmbeddedSurface render(mesh, read_obj(std::string(TISSUE_MESH_DIR) + "/frog_surface.obj"),
                         default_max_outside_m(mesh));
  Eigen::VectorXd positions(3 * mesh.vertex_count());
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    positions.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<size_t>(v)] +
                                  Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
  }
  for (auto _ : state) {
    render.update(positions);
    benchmark::DoNotOptimize(render.normals().data());
  }
  state.counters["triangles"] = static_cast<double>(render.surface().triangles.size());
}
BENCHMARK(BM_RenderSurfaceMap)->Unit(benchmark::kMicrosecond);

// Issue 22: the frog at rest cut by full-height vertical strokes of the volume cutter (40 blade
// steps each, every stroke its own session), and its render surface (meshes/frog_surface.obj).
struct FrogStrokes {
  TetMesh mesh = read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
  SurfaceMesh surface = extract_surface(mesh);
  TetAdjacency adjacency = build_adjacency(mesh);
  Eigen::VectorXd rest = rest_positions(mesh);
  SurfaceBvh bvh{surface.triangles, rest};
  TriangleSurface render_surface = read_obj(std::string(TISSUE_MESH_DIR) + "/frog_surface.obj");
  std::optional<DeformableBody> body{std::in_place, mesh, BodySettings{}};
  DynamicState dynamics = at_rest(*body);

  static Eigen::VectorXd rest_positions(const TetMesh& mesh) {
    Eigen::VectorXd rest(3 * mesh.vertex_count());
    for (int v = 0; v < mesh.vertex_count(); ++v) rest.segment<3>(3 * v) = mesh.rest_positions_m[static_cast<size_t>(v)];
    return rest;
  }
  static DynamicState at_rest(const DeformableBody& body) {
    DynamicState dynamics;
    dynamics.displacement_m = Eigen::VectorXd::Zero(body.dof_count());
    dynamics.velocity_m_per_s = Eigen::VectorXd::Zero(body.dof_count());
    return dynamics;
  }
  /// Back to the uncut frog.
  void reset() {
    body.emplace(mesh, BodySettings{});
    dynamics = at_rest(*body);
  }
  /// Strokes (x, y from -> to) through the whole height; `after_cut` after each blade step that cut.
  void cut(const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>>& strokes,
           const std::function<void()>& after_cut = {}) {
    VolumeCutter cutter(mesh, adjacency, surface);
    for (const auto& [from, to] : strokes) {
      Blade previous;
      for (int n = 0; n <= 40; ++n) {
        const Eigen::Vector2d at = from + (to - from) * n / 40;
        const Blade blade{Eigen::Vector3d(at.x(), at.y(), -0.03), Eigen::Vector3d(at.x(), at.y(), 0.06)};
        cutter.step(n == 0 ? blade : previous, blade, rest, bvh);
        previous = blade;
        if (cutter.new_cuts().empty()) continue;
        body->enrich(cutter.new_cuts(), dynamics);
        if (after_cut) after_cut();
      }
      cutter.end_cut(rest);  // the stroke ends where the blade is
      if (cutter.new_cuts().empty()) continue;
      body->enrich(cutter.new_cuts(), dynamics);
      if (after_cut) after_cut();
    }
  }
  [[nodiscard]] CutRenderSurface render() const { return {mesh, render_surface, default_max_outside_m(mesh)}; }
};

// Two strokes crossing on the back: an X.
const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> X_STROKES{
    {Eigen::Vector2d(-0.0301, -0.0702), Eigen::Vector2d(0.0399, 0.0698)},
    {Eigen::Vector2d(-0.0301, 0.0698), Eigen::Vector2d(0.0399, -0.0702)}};

// Issue 22: the render surface cut with the tets on the frog after the X: arg 0 re-meshes it for
// all the cuts from scratch (rebuild), arg 1 maps it onto the state (update, pieces included).
void BM_CutRenderSurface(benchmark::State& state) {
  FrogStrokes frog;
  frog.cut(X_STROKES);
  const CutRenderSurface fresh = frog.render();
  std::optional<CutRenderSurface> render(fresh);
  render->rebuild(*frog.body);
  for (auto _ : state) {
    if (state.range(0) == 0) {  // a fresh copy each time: from scratch
      state.PauseTiming();
      render.emplace(fresh);
      state.ResumeTiming();
      render->rebuild(*frog.body);
    } else {
      render->update(*frog.body, frog.dynamics.displacement_m);
    }
    benchmark::DoNotOptimize(render->triangles().data());
  }
  state.counters["triangles"] = static_cast<double>(render->triangles().size());
  state.counters["cut_tets"] = frog.body->cut_tet_count();
}
BENCHMARK(BM_CutRenderSurface)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Issue 22: re-meshing a step's new cuts (the target: <= 1 ms), as a session does: the X made blade
// step by blade step, the render surface re-meshed after each step that cut (only those re-meshes
// timed; the strokes start again when they are done).
void BM_CutRenderSurfaceStep(benchmark::State& state) {
  FrogStrokes frog;
  const CutRenderSurface fresh = frog.render();
  long remeshes = 0, incremental = 0;
  while (state.KeepRunning()) {
    state.PauseTiming();
    frog.reset();
    CutRenderSurface render(fresh);
    render.rebuild(*frog.body);
    frog.cut(X_STROKES, [&] {
      state.ResumeTiming();
      render.rebuild(*frog.body);
      state.PauseTiming();
      ++remeshes;
      incremental += render.rebuilt_from_scratch() ? 0 : 1;
    });
    state.ResumeTiming();
  }
  state.counters["remeshes_per_iteration"] = static_cast<double>(remeshes) / static_cast<double>(state.iterations());
  state.counters["incremental_share"] = static_cast<double>(incremental) / static_cast<double>(remeshes);
}
BENCHMARK(BM_CutRenderSurfaceStep)->Unit(benchmark::kMillisecond);

// A careless hand on the frog: N strokes along y spread over the body's length, then N across them.
std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> hatched_strokes(int strokes) {
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> hatched;
  for (int k = 0; k < strokes; ++k) {
    const double x = -0.025 + 0.06 * (k + 0.5) / strokes;
    hatched.emplace_back(Eigen::Vector2d(x, -0.0702), Eigen::Vector2d(x, 0.0698));
  }
  for (int k = 0; k < strokes; ++k) {
    const double y = -0.05 + 0.10 * (k + 0.5) / strokes;
    hatched.emplace_back(Eigen::Vector2d(-0.0301, y), Eigen::Vector2d(0.0399, y));
  }
  return hatched;
}

// Issue 41: the forces and tangent of the frog after N + N hatched strokes (0: uncut) on one thread
// or a team of two (range(1)): the cut tets are assembled in the uncut tets' phases.
void BM_HatchedForcesAndTangent(benchmark::State& state) {
  FrogStrokes frog;
  frog.cut(hatched_strokes(static_cast<int>(state.range(0))));
  std::optional<WorkTeam> team;
  if (state.range(1) == 2) team.emplace(2);
  frog.body->lend_work_team(team ? &*team : nullptr);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> jitter(-1e-4, 1e-4);
  const Eigen::VectorXd displacement =
      Eigen::VectorXd::NullaryExpr(frog.body->dof_count(), [&] { return jitter(rng); });
  Eigen::VectorXd forces;
  for (auto _ : state) {
    frog.body->evaluate(displacement, forces, true);
    benchmark::DoNotOptimize(forces.data());
  }
  state.counters["cut_tets"] = frog.body->cut_tet_count();
  state.counters["dofs"] = frog.body->dof_count();
}
BENCHMARK(BM_HatchedForcesAndTangent)->ArgsProduct({{0, 30}, {1, 2}})->Unit(benchmark::kMicrosecond);

// Issue 41: the energy guard's pass over the same hatched frog (its elastic energy, the pieces'
// rotations from copies of their warm starts).
void BM_HatchedElasticEnergy(benchmark::State& state) {
  FrogStrokes frog;
  frog.cut(hatched_strokes(static_cast<int>(state.range(0))));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> jitter(-1e-4, 1e-4);
  const Eigen::VectorXd displacement =
      Eigen::VectorXd::NullaryExpr(frog.body->dof_count(), [&] { return jitter(rng); });
  for (auto _ : state) benchmark::DoNotOptimize(frog.body->potential_energy_j(displacement));
  state.counters["cut_tets"] = frog.body->cut_tet_count();
}
BENCHMARK(BM_HatchedElasticEnergy)->Arg(0)->Arg(30)->Unit(benchmark::kMicrosecond);

// Issue 22: re-meshing the render surface from scratch after a careless hand.
void BM_CutRenderSurfaceHatched(benchmark::State& state) {
  FrogStrokes frog;
  frog.cut(hatched_strokes(static_cast<int>(state.range(0))));
  const CutRenderSurface fresh = frog.render();
  std::optional<CutRenderSurface> render;
  for (auto _ : state) {
    state.PauseTiming();
    render.emplace(fresh);
    state.ResumeTiming();
    render->rebuild(*frog.body);
    benchmark::DoNotOptimize(render->triangles().data());
  }
  state.counters["triangles"] = static_cast<double>(render->triangles().size());
  state.counters["cut_tets"] = frog.body->cut_tet_count();
  state.counters["open_loops"] = render->open_loop_count();
}
BENCHMARK(BM_CutRenderSurfaceHatched)->Arg(1)->Arg(3)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tissue

BENCHMARK_MAIN();
