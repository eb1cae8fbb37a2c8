// tissue-cut-bench: the dissertation's tables 6.3 and 6.4 on our frog. For each scenario (1-3
// scripted scalpel strokes): the system before and after (size, enriched vertices, non-zeros,
// median step time), the volume cutter's time and newly cut tets per cutting step, and the worst
// step during the cuts against a normal step. Prints a JSON array.
#include "app_main.hpp"
#include "cut_scenarios.hpp"
#include "run_statistics.hpp"
#include "scene_options.hpp"
#include "core/fixed_region.hpp"

#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>
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

  const double rest_ms = 1e3 * (worst.total_s - worst.cut_s - worst.enrich_s - worst.dynamics.assembly_s -
                                worst.dynamics.solve_s - worst.contact_s - worst.positions_s);
  const nlohmann::ordered_json result = {
      {"scenario", scenario.name},
      {"cuts", scenario.strokes.size()},
      {"solver", options.scene.solver},
      {"dt_s", options.scene.step_size_s},
      {"speed_m_per_s", options.stroke.speed_m_per_s},
      {"dofs_before", dofs_before},
      {"dofs_after", dofs_after},
      {"enriched_vertices", tissue.body().enriched_dof_count()},
      {"cut_tets", tissue.body().cut_tet_count()},
      {"nonzeros_before", nonzeros_before},
      {"nonzeros_after", nonzeros_after},
      {"fill_before", fill(nonzeros_before, dofs_before)},
      {"fill_after", fill(nonzeros_after, dofs_after)},
      {"ms_per_step_before", ms_before},
      {"ms_per_step_after", ms_after},
      {"stroke_steps", steps},
      {"cutting_steps", cutter_ms.size()},
      {"cutter_ms", {{"mean", cutter.mean}, {"median", cutter.median}, {"max", cutter.max}}},
      {"new_tets_per_cutting_step", {{"mean", tets.mean}, {"median", tets.median}, {"max", tets.max}}},
      {"step_ms_during_cuts", {{"median", during.median}, {"max", worst_ms}}},
      {"worst_over_normal", worst_ms / ms_before},
      {"worst_step_ms",
       {{"cutter", 1e3 * worst.cut_s},
        {"enrich", 1e3 * worst.enrich_s},
        {"assembly", 1e3 * worst.dynamics.assembly_s},
        {"solve", 1e3 * worst.dynamics.solve_s},
        {"contact", 1e3 * worst.contact_s},
        {"positions", 1e3 * worst.positions_s},
        {"rest", rest_ms},
        {"new_tets", worst.cut.newly_cut_tets}}},
      {"matrix_relayouts", relayouts},
      {"ignored_cuts", ignored}};
  // One element of the array per scenario as it finishes (a long run shows its progress).
  std::printf("  %s%s\n", result.dump().c_str(), last ? "" : ",");
  std::fflush(stdout);
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
  return tissue::apps::parse_and_run(app, argc, argv, "tissue-cut-bench", [&] {
    std::vector<tissue::apps::CutScenario> scenarios = tissue::apps::frog_cut_scenarios();
    if (!options.only.empty()) {
      std::erase_if(scenarios, [&](const auto& s) { return s.name != options.only; });
      if (scenarios.empty()) throw std::invalid_argument("no scenario named '" + options.only + "'");
    }
    std::printf("[\n");
    for (size_t k = 0; k < scenarios.size(); ++k) run_scenario(options, scenarios[k], k + 1 == scenarios.size());
    std::printf("]\n");
    return 0;
  });
}
