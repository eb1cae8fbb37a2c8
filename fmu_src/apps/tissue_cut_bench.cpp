// tissue-cut-bench: the dissertation's tables 6.3 and 6.4 on our frog. For each scenario (1-3
// scripted scalpel strokes): the system before and after (size, enriched vertices, non-zeros,
// median step time), the volume cutter's time and newly cut tets per cutting step, and the worst
// step during the cuts against a normal step. Prints a JSON array.
#include "apps/cut_scenarios.hpp"
#include "apps/run_statistics.hpp"
#include "apps/scene_options.hpp"
#include "core/fixed_region.hpp"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>

namespace {

using tissue::apps::summarize;
using tissue::apps::Summary;

struct BenchOptions {
  tissue::apps::SceneOptions scene;
  tissue::apps::StrokeSettings stroke;
  double blade_length_m = 0.08;
  int settle_steps = 50;
  double pinned_fraction = 0.25;  ///< of the z extent: the vertices pinned at the bottom
  std::string only;
};

double median_step_ms(tissue::Tissue& tissue, int steps) {
  std::vector<double> ms;
  for (int n = 0; n < steps; ++n) ms.push_back(1e3 * tissue.step().total_s);
  return summarize(ms).median;
}

void run_scenario(const BenchOptions& options, const tissue::apps::CutScenario& scenario, bool last) {
  tissue::apps::Scene scene = tissue::apps::make_scene(options.scene);
  // Pinned on the dissection tray by its belly: the lowest part of the body, so the pieces stay
  // where the strokes expect them (held by the feet, the soft frog sags below the blade).
  scene.settings.body.fixed_vertices = tissue::vertices_at_minimum(scene.mesh, 2, options.pinned_fraction);
  scene.settings.interaction.blade_length_m = options.blade_length_m;
  tissue::Tissue tissue(std::move(scene.mesh), scene.settings);
  const int dofs_before = tissue.body().dof_count();
  const long nonzeros_before = tissue.body().tangent().nonzeros();
  const double ms_before = median_step_ms(tissue, options.settle_steps);

  std::vector<double> cutter_ms, new_tets, step_ms;
  double worst_ms = 0.0;
  tissue::TissueStepReport worst;
  int relayouts = 0;
  int ignored = 0;
  int steps = 0;
  for (const tissue::apps::CutStroke& stroke : scenario.strokes) {
    steps += tissue::apps::run_stroke(tissue, stroke, options.stroke, [&](const tissue::TissueStepReport& report) {
      step_ms.push_back(1e3 * report.total_s);
      if (1e3 * report.total_s > worst_ms) {
        worst_ms = 1e3 * report.total_s;
        worst = report;
      }
      if (report.cut.cut_id >= 0) {  // a step of an open cutting session
        cutter_ms.push_back(1e3 * report.cut_s);
        new_tets.push_back(report.cut.newly_cut_tets);
      }
      relayouts += report.enrichment.matrix_relayout ? 1 : 0;
      ignored += report.cut.ignored_cuts;
    });
  }
  const int dofs_after = tissue.body().dof_count();
  const long nonzeros_after = tissue.body().tangent().nonzeros();
  const double ms_after = median_step_ms(tissue, options.settle_steps);
  const Summary cutter = summarize(cutter_ms);
  const Summary tets = summarize(new_tets);
  const Summary during = summarize(step_ms);
  const auto fill = [](long nonzeros, int n) { return static_cast<double>(nonzeros) / (double(n) * double(n)); };

  std::printf("  {\"scenario\": \"%s\", \"cuts\": %zu, \"solver\": \"%s\", \"dt_s\": %g, \"speed_m_per_s\": %g,\n",
              scenario.name.c_str(), scenario.strokes.size(), options.scene.solver.c_str(), options.scene.step_size_s,
              options.stroke.speed_m_per_s);
  std::printf("   \"dofs_before\": %d, \"dofs_after\": %d, \"enriched_vertices\": %d, \"cut_tets\": %d,\n",
              dofs_before, dofs_after, tissue.body().enriched_dof_count(), tissue.body().cut_tet_count());
  std::printf("   \"nonzeros_before\": %ld, \"nonzeros_after\": %ld, \"fill_before\": %.5f, \"fill_after\": %.5f,\n",
              nonzeros_before, nonzeros_after, fill(nonzeros_before, dofs_before), fill(nonzeros_after, dofs_after));
  std::printf("   \"ms_per_step_before\": %.4f, \"ms_per_step_after\": %.4f,\n", ms_before, ms_after);
  std::printf(
      "   \"stroke_steps\": %d, \"cutting_steps\": %zu, \"cutter_ms\": {\"mean\": %.4f, \"median\": %.4f, "
      "\"max\": %.4f},\n",
      steps, cutter_ms.size(), cutter.mean, cutter.median, cutter.max);
  std::printf("   \"new_tets_per_cutting_step\": {\"mean\": %.3f, \"median\": %.1f, \"max\": %.0f},\n", tets.mean,
              tets.median, tets.max);
  std::printf("   \"step_ms_during_cuts\": {\"median\": %.4f, \"max\": %.4f}, \"worst_over_normal\": %.3f,\n",
              during.median, worst_ms, worst_ms / ms_before);
  std::printf(
      "   \"worst_step_ms\": {\"cutter\": %.4f, \"enrich\": %.4f, \"assembly\": %.4f, \"solve\": %.4f, "
      "\"contact\": %.4f, \"positions\": %.4f, \"rest\": %.4f, \"new_tets\": %d},\n",
      1e3 * worst.cut_s, 1e3 * worst.enrich_s, 1e3 * worst.dynamics.assembly_s, 1e3 * worst.dynamics.solve_s,
      1e3 * worst.contact_s, 1e3 * worst.positions_s,
      1e3 * (worst.total_s - worst.cut_s - worst.enrich_s - worst.dynamics.assembly_s - worst.dynamics.solve_s -
             worst.contact_s - worst.positions_s),
      worst.cut.newly_cut_tets);
  std::printf("   \"matrix_relayouts\": %d, \"ignored_cuts\": %d}%s\n", relayouts, ignored, last ? "" : ",");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tissue-cut-bench: scripted scalpel cuts through the frog (tables 6.3 and 6.4), JSON out"};
  BenchOptions options;
  options.scene.gravity = "0,0,-9.81";
  options.scene.tolerance = 1e-3;
  options.scene.max_iterations = 10;
  tissue::apps::add_scene_options(app, options.scene);
  app.add_option("--speed", options.stroke.speed_m_per_s, "scalpel speed [m/s]")->check(CLI::PositiveNumber);
  app.add_option("--blade-length", options.blade_length_m, "length of the cutting edge [m]")
      ->check(CLI::PositiveNumber);
  app.add_option("--settle-steps", options.settle_steps, "steps timed before and after the cuts")
      ->check(CLI::Range(1, 100000));
  app.add_option("--pinned-fraction", options.pinned_fraction, "of the z extent pinned at the bottom")
      ->check(CLI::Range(1e-6, 1.0));
  app.add_option("--only", options.only, "run only the scenario of this name");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }
  try {
    std::vector<tissue::apps::CutScenario> scenarios = tissue::apps::frog_cut_scenarios();
    if (!options.only.empty()) {
      std::erase_if(scenarios, [&](const auto& s) { return s.name != options.only; });
      if (scenarios.empty()) throw std::invalid_argument("no scenario named '" + options.only + "'");
    }
    std::printf("[\n");
    for (size_t k = 0; k < scenarios.size(); ++k) run_scenario(options, scenarios[k], k + 1 == scenarios.size());
    std::printf("]\n");
    return 0;
  } catch (const tissue::IntegrationError& error) {
    std::cerr << "tissue-cut-bench: step failed: " << error.what() << '\n';
    return 1;
  } catch (const std::exception& error) {
    std::cerr << "tissue-cut-bench: " << error.what() << '\n';
    return 2;
  }
}
