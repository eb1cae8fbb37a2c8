// The opt-in second thread of a step (IntegratorSettings::threads): the work team itself, the
// assembly's split of the mesh, and that two threads (assembly and CG) give bitwise the steps of one.
#include "core/fixed_region.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/system/work_team.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace tissue {
namespace {

TEST(WorkTeam, RunsEveryPartOncePerJobPartZeroOnTheCaller) {
  WorkTeam team(2);
  int on_the_worker = 0;
  for (int job = 0; job < 1000; ++job) {
    std::vector<int> runs(2, 0);
    std::vector<std::thread::id> ids(2);
    auto count = [&](int part) {
      ++runs[static_cast<size_t>(part)];
      ids[static_cast<size_t>(part)] = std::this_thread::get_id();
    };
    team.run(count);
    ASSERT_EQ(runs, std::vector<int>({1, 1})) << "job " << job;
    ASSERT_EQ(ids[0], std::this_thread::get_id());
    on_the_worker += ids[1] != std::this_thread::get_id() ? 1 : 0;
  }
  // Part 1 goes to the worker unless the caller finds it unstarted after part 0 (on an idle machine
  // a spinning worker takes most; on a busy one it may get none: the caller then runs them all).
  EXPECT_EQ(on_the_worker + team.parts_taken_over(), 1000);
}

// A worker the scheduler has not run yet (preempted by the haptic thread, or waking from a block)
// must not hold the step up: the caller, done with part 0, runs part 1 itself. Here the worker is
// asleep before each job (it blocks after 100 us idle; waking it takes microseconds), and part 0 is
// empty, so the caller usually claims part 1 first. Before parts were claimed, the caller
// waited for the worker's wake-up at every job (parts_taken_over stayed 0).
TEST(WorkTeam, TheCallerRunsAPartNoWorkerHasStarted) {
  WorkTeam team(2);
  std::vector<std::thread::id> part_one_ran_on;
  for (int job = 0; job < 50; ++job) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // the worker blocks meanwhile
    std::vector<int> runs(2, 0);
    auto record = [&](int part) {
      ++runs[static_cast<size_t>(part)];
      if (part == 1) part_one_ran_on.push_back(std::this_thread::get_id());
    };
    team.run(record);
    ASSERT_EQ(runs, std::vector<int>({1, 1})) << "job " << job;
  }
  const long on_the_caller = std::count(part_one_ran_on.begin(), part_one_ran_on.end(), std::this_thread::get_id());
  std::printf("part 1 run by the caller in %ld of 50 jobs\n", on_the_caller);
  EXPECT_EQ(on_the_caller, team.parts_taken_over());
  // Nearly all 50 here; at least one on a busy machine, where a woken worker may be run on the
  // caller's core at once and claim first.
  EXPECT_GT(on_the_caller, 0);
}

// The scheduler states ('R' running, 'S' sleeping, ...) of this process's threads other than the caller.
std::vector<char> other_thread_states() {
  std::vector<char> states;
  const std::string self = std::to_string(gettid());
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    if (task.path().filename() == self) continue;
    std::ifstream stat(task.path() / "stat");
    std::string line;
    std::getline(stat, line);
    const size_t name_end = line.rfind(')');  // "tid (name) S ..."
    if (name_end != std::string::npos && name_end + 2 < line.size()) states.push_back(line[name_end + 2]);
  }
  return states;
}

// A member waiting for work (or the caller waiting for a member) spins only briefly, then blocks
// in the kernel, so that it never burns a core its partner (or the CHOLMOD refresh thread, or
// another program) needs. Before the fix waiting members spun, then yield()ed without end: with
// both members on one core, 40 hand-overs of a step took 4-40 ms on this machine's two cores.
TEST(WorkTeam, AnIdleMemberSleepsInsteadOfSpinning) {
  WorkTeam team(2);
  int runs[2] = {0, 0};
  auto job = [&](int member) { ++runs[member]; };
  team.run(job);
  ASSERT_EQ(runs[0] + runs[1], 2);
  // The worker now waits for the next job; within two seconds it must be asleep ('S'), as every
  // other thread of the process (a sanitizer's own background thread included).
  const auto all_asleep = [](const std::vector<char>& states) {
    return !states.empty() && std::all_of(states.begin(), states.end(), [](char state) { return state == 'S'; });
  };
  std::vector<char> states;
  for (int poll = 0; poll < 200; ++poll) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    states = other_thread_states();
    if (all_asleep(states)) break;
  }
  EXPECT_TRUE(all_asleep(states)) << "the idle worker is still running (spinning): "
                                  << std::string(states.begin(), states.end());
}

TEST(WorkTeam, ThreadSettingsOutsideOneToTwoAreRefused) {
  EXPECT_THROW(WorkTeam{0}, ParameterError);
  EXPECT_THROW(WorkTeam{MAX_STEP_THREADS + 1}, ParameterError);
  TissueSettings settings;
  settings.integrator.threads = 3;
  EXPECT_THROW(validate(settings), ParameterError);
  settings.integrator.threads = 0;
  EXPECT_THROW(validate(settings), ParameterError);
}

TetMesh frog() { return read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg"); }

TEST(AssemblySplit, EveryTetOnceAndTheHalvesOfAPhaseShareNoVertex) {
  const TetMesh mesh = frog();
  const CorotationalElasticity elasticity(mesh, Material{1.0e5, 0.4, 1000.0});
  std::vector<int> seen(static_cast<size_t>(mesh.tet_count()), 0);
  for (const CorotationalElasticity::AssemblyPhase& phase : elasticity.assembly_phases()) {
    std::vector<int> vertex_part(static_cast<size_t>(mesh.vertex_count()), -1);
    for (int part = 0; part < CorotationalElasticity::ASSEMBLY_PARTS; ++part) {
      for (const int k : phase[static_cast<size_t>(part)]) {  // storage indices
        const int t = elasticity.tet_id(k);
        ++seen[static_cast<size_t>(t)];
        for (const int v : mesh.tets[static_cast<size_t>(t)]) {
          int& owner = vertex_part[static_cast<size_t>(v)];
          EXPECT_TRUE(owner == -1 || owner == part) << "vertex " << v << " in both halves of a phase";
          owner = part;
        }
      }
    }
    std::printf("frog: a phase of %zu + %zu tets\n", phase[0].size(), phase[1].size());
  }
  for (const int k : elasticity.serial_tets()) ++seen[static_cast<size_t>(elasticity.tet_id(k))];
  EXPECT_EQ(seen, std::vector<int>(seen.size(), 1));
  // The split is worth having: few tets are left to one thread.
  EXPECT_LT(elasticity.serial_tets().size(), static_cast<size_t>(mesh.tet_count()) / 20);
  std::printf("frog: %zu tets alone\n", elasticity.serial_tets().size());
}

// The frog swinging under gravity at the real-time setting, with the large-turn protections (so the
// Newton corrections and the energy guard run with the team too), with one and with two threads.
DynamicState run(int threads, LinearSolverKind solver = LinearSolverKind::pcg) {
  TetMesh mesh = frog();
  TissueSettings settings;
  settings.body.material = {1.0e5, 0.4, 1000.0};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.01);
  settings.solver.pcg = {1e-3, 10};
  settings.solver.kind = solver;
  settings.step_size_s = 0.01;
  settings.integrator.threads = threads;
  Tissue tissue(std::move(mesh), settings);
  for (int step = 0; step < 60; ++step) tissue.step();
  return tissue.state();
}

// Jacobi PCG splits its products, updates and preconditioning; pcgCholesky its products and
// updates around the factor's solve (and its refresh runs beside them: the same factor is picked up
// at the same setup, bitwise, which failed while its solves and the refresh shared OpenBLAS);
// CHOLMOD keeps one thread for the solve.
TEST(StepThreads, TwoThreadsGiveBitwiseTheStepsOfOne) {
  for (const LinearSolverKind solver :
       {LinearSolverKind::pcg, LinearSolverKind::cholmod, LinearSolverKind::pcg_cholesky}) {
    SCOPED_TRACE(std::string(to_string(solver)));
    const DynamicState one = run(1, solver);
    const DynamicState two = run(2, solver);
    ASSERT_GT(one.displacement_m.cwiseAbs().maxCoeff(), 1e-3);
    EXPECT_TRUE(one.displacement_m == two.displacement_m);
    EXPECT_TRUE(one.velocity_m_per_s == two.velocity_m_per_s);
  }
}

// The frog held at its tail, cut by a scalpel drawn across it and then along it (cut tets cut again
// where the strokes cross), swinging on after: the cut tets' assembly, energies and turns run in the
// uncut tets' phases (XfemElasticity::set_assembly_lists), with the shipped two-level solver.
DynamicState run_cut(int threads) {
  TetMesh mesh = frog();
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1e9);
  Eigen::Vector3d high = -low;
  for (const Eigen::Vector3d& p : mesh.rest_positions_m) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  TissueSettings settings;
  settings.body.material = {3.0e5, 0.4, 1000.0};
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, 0.3);
  settings.step_size_s = 0.002;
  settings.interaction.blade_length_m = 3.0 * (high.z() - low.z());
  settings.integrator.threads = threads;
  Tissue tissue(std::move(mesh), settings);
  const double z = low.z() - (high.z() - low.z());
  const auto stroke = [&](const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
    constexpr int STEPS = 40;
    for (int n = 0; n <= STEPS; ++n) {
      const Eigen::Vector3d at = from + (to - from) * n / STEPS;
      tissue.set_tool(ToolPose{Eigen::Vector3d(at.x(), at.y(), z), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
      tissue.step();
    }
    tissue.set_tool(ToolPose{Eigen::Vector3d(to.x(), to.y(), z), Eigen::Quaterniond::Identity(), ToolMode::none});
  };
  const Eigen::Vector3d size = high - low;
  const double x = low.x() + 0.6 * size.x();
  stroke({x, low.y() - 0.01, 0.0}, {x, high.y() + 0.01, 0.0});
  const double y = low.y() + 0.5 * size.y();
  stroke({low.x() + 0.4 * size.x(), y, 0.0}, {high.x() + 0.01, y, 0.0});
  for (int step = 0; step < 30; ++step) tissue.step();
  EXPECT_GT(tissue.body().xfem().cut_tet_count(), 40);
  std::printf("cut frog on %d thread(s): %d cut tets made\n", threads, tissue.body().xfem().cut_tet_count());
  return tissue.state();
}

TEST(StepThreads, TwoThreadsGiveBitwiseTheStepsOfOneThroughCuts) {
  const DynamicState one = run_cut(1);
  const DynamicState two = run_cut(2);
  ASSERT_GT(one.displacement_m.cwiseAbs().maxCoeff(), 1e-3);
  ASSERT_EQ(one.displacement_m.size(), two.displacement_m.size());
  EXPECT_TRUE(one.displacement_m == two.displacement_m);
  EXPECT_TRUE(one.velocity_m_per_s == two.velocity_m_per_s);
}

}  // namespace
}  // namespace tissue
