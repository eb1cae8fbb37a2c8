// tissue-demo: the frog dissection (the main job until the real-time host of issue 5 exists).
// The frog (embedded by default) lies pinned by its belly on the tray under gravity; a probe
// presses its back (god-object contact: force and contact stiffness printed), then a scalpel makes
// the strokes of one of the cut scenarios (tissue-cut-bench's), and the pieces settle. Prints one
// line per phase and every --print-every steps, and can write the final surface as OBJ.
#include "app_main.hpp"
#include "cut_scenarios.hpp"
#include "run_statistics.hpp"
#include "scene_options.hpp"
#include "core/fixed_region.hpp"
#include "core/mesh/topology.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>

namespace {

struct DemoOptions {
  tissue::apps::SceneOptions scene;
  tissue::apps::StrokeSettings stroke;
  std::string scenario = "test5-body-and-head";
  double pinned_fraction = 0.25;
  double probe_depth_m = 0.003;
  int print_every = 10;
  std::string surface_obj;
};

// Wavefront OBJ of the boundary triangles at the given vertex positions (all vertices written, so
// the indices are the mesh's own, 1-based as OBJ wants). Cut tets are drawn with their real vertices.
void write_surface_obj(const std::string& path, const tissue::Tissue& tissue) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  const Eigen::VectorXd& x = tissue.current_positions_m();
  out << "# tissue-demo surface, metres\n";
  for (int v = 0; v < tissue.body().mesh().vertex_count(); ++v) {
    out << "v " << x(3 * v) << ' ' << x(3 * v + 1) << ' ' << x(3 * v + 2) << '\n';
  }
  for (const auto& triangle : tissue.surface().triangles) {
    out << "f " << triangle[0] + 1 << ' ' << triangle[1] + 1 << ' ' << triangle[2] + 1 << '\n';
  }
}

class Printer {
 public:
  Printer(const tissue::Tissue& tissue, int every) : m_tissue(tissue), m_every(every) {
    std::printf("%-8s %6s %8s %9s %9s %9s %10s %12s %8s\n", "phase", "step", "time_s", "cut_tets", "enriched", "dofs",
                "force_N", "Kc_normal", "step_ms");
  }
  void operator()(const char* phase, const tissue::TissueStepReport& report, bool force_print = false) {
    ++m_step;
    m_step_ms.push_back(1e3 * report.total_s);
    if (!force_print && m_step % m_every != 0) return;
    const tissue::ContactOutput& contact = m_tissue.contact();
    const double normal_stiffness =
        contact.active ? contact.normal.dot(contact.stiffness_n_per_m * contact.normal) : 0.0;
    std::printf("%-8s %6d %8.3f %9d %9d %9d %10.4f %12.4g %8.3f\n", phase, m_step, m_tissue.time_s(),
                m_tissue.body().cut_tet_count(), m_tissue.body().enriched_dof_count(), m_tissue.body().dof_count(),
                contact.force_on_tool_n.norm(), normal_stiffness, 1e3 * report.total_s);
  }
  [[nodiscard]] const std::vector<double>& step_ms() const { return m_step_ms; }

 private:
  const tissue::Tissue& m_tissue;
  int m_every;
  int m_step = 0;
  std::vector<double> m_step_ms;
};

int run(const DemoOptions& options) {
  tissue::apps::Scene scene = tissue::apps::make_scene(options.scene);
  scene.settings.body.fixed_vertices = tissue::vertices_at_minimum(scene.mesh, 2, options.pinned_fraction);
  scene.settings.interaction.blade_length_m = 0.08;
  std::vector<tissue::apps::CutScenario> scenarios = tissue::apps::frog_cut_scenarios();
  const auto scenario =
      std::find_if(scenarios.begin(), scenarios.end(), [&](const auto& s) { return s.name == options.scenario; });
  if (scenario == scenarios.end()) throw tissue::ParameterError("no cut scenario named '" + options.scenario + "'");
  std::printf(
      "tissue-demo: %s, %d vertices, %d tets, %zu pinned (z within %.0f%% of the bottom), E = %.3g Pa, nu = %.3g, "
      "rho = %.4g kg/m^3, dt = %.4g s, solver %s; cuts: %s\n",
      scene.mesh_name.c_str(), scene.mesh.vertex_count(), scene.mesh.tet_count(),
      scene.settings.body.fixed_vertices.size(), 100.0 * options.pinned_fraction,
      options.scene.material.young_modulus_pa, options.scene.material.poisson_ratio,
      options.scene.material.density_kg_per_m3, options.scene.step_size_s, options.scene.solver.c_str(),
      scenario->name.c_str());
  tissue::Tissue tissue(std::move(scene.mesh), scene.settings);
  Printer print(tissue, options.print_every);

  for (int n = 0; n < options.scene.steps; ++n) print("settle", tissue.step());

  // Probe: from 2 cm above the highest point of the back straight down to probe_depth_m below it.
  const Eigen::VectorXd& x = tissue.current_positions_m();
  int top = 0;
  for (int v = 0; v < tissue.body().mesh().vertex_count(); ++v) {
    if (std::abs(x(3 * v)) < 0.01 && x(3 * v + 2) > x(3 * top + 2)) top = v;
  }
  const Eigen::Vector3d above = x.segment<3>(3 * top) + Eigen::Vector3d(0.0, 0.0, 0.02);
  const int press_steps = 40;
  for (int n = 0; n <= press_steps; ++n) {
    const double depth = (0.02 + options.probe_depth_m) * n / press_steps;
    tissue.set_tool(
        {above - Eigen::Vector3d(0.0, 0.0, depth), Eigen::Quaterniond::Identity(), tissue::ToolMode::probe});
    print("probe", tissue.step());
  }
  for (int n = 0; n < 30; ++n) print("hold", tissue.step(), n == 29);
  tissue.set_tool({above, Eigen::Quaterniond::Identity(), tissue::ToolMode::probe});
  print("lift", tissue.step(), true);

  for (const tissue::apps::CutStroke& stroke : scenario->strokes) {
    tissue::apps::run_stroke(tissue, stroke, options.stroke,
                             [&](const tissue::TissueStepReport& report) { print("cut", report); });
    print("cut-end", tissue.step(), true);
  }
  for (int n = 0; n < options.scene.steps; ++n) print("settle", tissue.step(), n + 1 == options.scene.steps);

  if (!options.surface_obj.empty()) {
    write_surface_obj(options.surface_obj, tissue);
    std::printf("tissue-demo: wrote the surface to %s\n", options.surface_obj.c_str());
  }
  const tissue::apps::Summary summary = tissue::apps::summarize(print.step_ms());
  std::printf(
      "tissue-demo: %zu steps, %.3f ms per step (median), %.3f ms (max); simulated %.3f s; %d tets cut, "
      "%d enriched vertices\n",
      print.step_ms().size(), summary.median, summary.max, tissue.time_s(), tissue.body().cut_tet_count(),
      tissue.body().enriched_dof_count());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tissue-demo: the frog dissection: pinned frog, a probe poke, then scalpel strokes"};
  DemoOptions options;
  options.scene.steps = 50;  // settling steps before the probe and after the cuts
  options.scene.step_size_s = 0.01;
  options.scene.damping = {1.0, 0.01};
  options.scene.gravity = "0,0,-9.81";
  options.scene.solver = "cholmod";  // exact solves, ~2x faster than strict PCG on the frog at this step
  tissue::apps::add_scene_options(app, options.scene);
  app.add_option("--scenario", options.scenario, "the cut scenario (see tissue-cut-bench)")->capture_default_str();
  app.add_option("--speed", options.stroke.speed_m_per_s, "scalpel speed [m/s]")->check(CLI::PositiveNumber);
  app.add_option("--probe-depth", options.probe_depth_m, "how deep the probe presses [m]")
      ->check(CLI::Range(0.0, 0.02));
  app.add_option("--pinned-fraction", options.pinned_fraction, "of the z extent pinned at the bottom")
      ->check(CLI::Range(1e-6, 1.0));
  app.add_option("--print-every", options.print_every, "Print one line every this many steps")->capture_default_str();
  app.add_option("--surface-obj", options.surface_obj, "Write the final surface as Wavefront OBJ to this file");
  return tissue::apps::parse_and_run(app, argc, argv, "tissue-demo", [&] {
    if (options.print_every < 1) throw tissue::ParameterError("--print-every must be >= 1");
    return run(options);
  });
}
