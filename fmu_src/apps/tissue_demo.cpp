// tissue-demo: the frog (embedded by default) dropped under gravity with one side held, printing
// per-step figures. The main job until the real-time host (issue 5) exists.
#include "apps/run_statistics.hpp"
#include "apps/scene_options.hpp"
#include "core/mesh/topology.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>

namespace {

// Wavefront OBJ of the boundary triangles at the given vertex positions (all vertices written, so
// the indices are the mesh's own, 1-based as OBJ wants).
void write_surface_obj(const std::string& path, const tissue::TetMesh& mesh, const Eigen::VectorXd& positions_m) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "# tissue-demo surface, metres\n";
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    out << "v " << positions_m(3 * v) << ' ' << positions_m(3 * v + 1) << ' ' << positions_m(3 * v + 2) << '\n';
  }
  for (const auto& triangle : tissue::extract_surface(mesh).triangles) {
    out << "f " << triangle[0] + 1 << ' ' << triangle[1] + 1 << ' ' << triangle[2] + 1 << '\n';
  }
}

int run(const tissue::apps::SceneOptions& options, int print_every, const std::string& surface_obj) {
  tissue::apps::Scene scene = tissue::apps::make_scene(options);
  std::printf(
      "tissue-demo: %s, %d vertices, %d tets, %zu fixed (x within %.0f%% of the minimum), E = %.3g Pa, "
      "nu = %.3g, rho = %.4g kg/m^3, dt = %.4g s, solver %s\n",
      scene.mesh_name.c_str(), scene.mesh.vertex_count(), scene.mesh.tet_count(),
      scene.settings.body.fixed_vertices.size(), 100.0 * options.fixed_fraction, options.material.young_modulus_pa,
      options.material.poisson_ratio, options.material.density_kg_per_m3, options.step_size_s, options.solver.c_str());
  tissue::Tissue tissue(std::move(scene.mesh), scene.settings);
  std::printf("%6s %9s %14s %14s %14s %6s %9s\n", "step", "time_s", "max_sag_m", "kinetic_J", "elastic_J", "cg_it",
              "step_ms");
  std::vector<double> step_ms;
  Eigen::VectorXd positions;
  for (int step = 1; step <= options.steps; ++step) {
    const auto start = std::chrono::steady_clock::now();
    const tissue::StepReport report = tissue.step().dynamics;
    step_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (step % print_every != 0 && step != options.steps) continue;
    const Eigen::VectorXd& u = tissue.state().displacement_m;
    double max_sag = 0.0;
    for (Eigen::Index i = 1; i < u.size(); i += 3) max_sag = std::max(max_sag, -u(i));
    std::printf("%6d %9.4f %14.6e %14.6e %14.6e %6d %9.3f\n", step, tissue.time_s(), max_sag, tissue.kinetic_energy_j(),
                tissue.elastic_energy_j(), report.solve.iterations, step_ms.back());
  }
  if (!surface_obj.empty()) {
    tissue.vertex_positions(positions);
    write_surface_obj(surface_obj, tissue.body().mesh(), positions);
    std::printf("tissue-demo: wrote the deformed surface to %s\n", surface_obj.c_str());
  }
  const tissue::apps::Summary summary = tissue::apps::summarize(step_ms);
  std::printf("tissue-demo: %d steps, %.3f ms per step (median), %.3f ms (max); simulated %.3f s\n", options.steps,
              summary.median, summary.max, tissue.time_s());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tissue-demo: drop the frog under gravity with one side fixed and print per-step figures"};
  tissue::apps::SceneOptions options;
  options.steps = 200;
  options.step_size_s = 0.01;
  options.fixed_fraction = 0.1;
  options.damping = {1.0, 0.01};
  options.solver = "cholmod";  // exact solves, ~2x faster than strict PCG on the frog at this step
  int print_every = 10;
  std::string surface_obj;
  tissue::apps::add_scene_options(app, options);
  app.add_option("--print-every", print_every, "Print one line every this many steps")->capture_default_str();
  app.add_option("--surface-obj", surface_obj, "Write the final surface as Wavefront OBJ to this file");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }
  try {
    if (print_every < 1) throw tissue::ParameterError("--print-every must be >= 1");
    return run(options, print_every, surface_obj);
  } catch (const tissue::IntegrationError& error) {
    std::cerr << "tissue-demo: step failed: " << error.what() << '\n';
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "tissue-demo: " << error.what() << '\n';
    return 2;
  }
}
