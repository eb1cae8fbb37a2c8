// run_compare (see compare.hpp): plan, reference, the runs on threads and ranks, gather, report.
#include "compare/compare.hpp"

#include "compare/compare_run.hpp"
#include "compare/compare_settings.hpp"
#include "importer/fmu_archive.hpp"
#include "importer/model_description.hpp"
#include "scenario/scenario.hpp"
#include "session/session.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdio>
#include <mutex>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace tissue::host {
namespace {

/// "compare: 7/24 runs, ida-klu-rtol1e-5 @ 1 ms ..." on one line (or one per run).
class ProgressLine {
 public:
  ProgressLine(std::ostream* out, bool in_place, std::size_t total, std::string prefix)
      : m_out(out), m_in_place(in_place), m_total(total), m_prefix(std::move(prefix)) {}
  void starting(const RunSpec& run) {
    if (m_out == nullptr) return;
    const std::lock_guard lock(m_mutex);
    show(m_prefix + std::to_string(m_done) + "/" + std::to_string(m_total) + " runs, " + run.setting + " @ " +
         step_label(run.step_s) + " ...");
  }
  void finished() {
    const std::lock_guard lock(m_mutex);
    ++m_done;
  }
  void end() {
    if (m_out == nullptr) return;
    const std::lock_guard lock(m_mutex);
    show(m_prefix + std::to_string(m_done) + "/" + std::to_string(m_total) + " runs done");
    if (m_in_place) *m_out << "\n";
    m_out->flush();
  }

 private:
  void show(const std::string& text) {
    if (m_in_place) {
      const std::size_t pad = m_width > text.size() ? m_width - text.size() : 0;
      *m_out << "\r" << text << std::string(pad, ' ');
      m_width = text.size();
    } else {
      *m_out << text << "\n";
    }
    m_out->flush();
  }

  std::ostream* m_out;
  bool m_in_place;
  std::size_t m_total, m_done = 0, m_width = 0;
  std::string m_prefix;
  std::mutex m_mutex;
};

CompareSettingsList choose_settings(const CompareOptions& options) {
  if (options.settings_file) {
    std::optional<CompareSettingsList> list = read_compare_table(*options.settings_file);
    if (!list) throw ScenarioError(options.settings_file->string() + ": has no [compare] table");
    return *list;
  }
  if (std::optional<CompareSettingsList> list = read_compare_table(options.scenario_file)) return *list;
  return default_settings();
}

ModelDescription tissue_description(const std::filesystem::path& fmu) {
  const FmuArchive archive(fmu);
  return load_model_description(archive.model_description_path());
}

CompareRow make_row(const RunSpec& run, const RunOutcome& outcome, const ModelDescription& tissue) {
  const SettingDescription d = describe_setting(run.parameters, tissue);
  CompareRow row;
  row.setting = run.setting;
  row.integrator = d.integrator;
  row.linear_solver = d.linear_solver;
  row.material_model = d.material_model;
  row.tolerance = d.tolerance;
  row.iteration_cap = d.iteration_cap;
  row.internal_step_s = run.step_s;
  row.cpu_s_per_sim_s = outcome.cpu_s_per_sim_s();
  if (outcome.errors.valid) {
    row.rms_error_m = outcome.errors.rms_error_m;
    row.max_error_m = outcome.errors.max_error_m;
    row.force_error_n = outcome.errors.force_error_n;
    row.energy_drift_j = outcome.errors.energy_drift_j;
  }
  row.iterations = outcome.iterations;
  row.failures = outcome.failures;
  row.note = outcome.note;
  return row;
}

/// The reference against itself (zero by construction; through the same code as every run).
ErrorMetrics self_comparison(const ReferenceTrace& reference) {
  ErrorAccumulator compare(reference);
  const std::size_t n = reference.vertex_count;
  for (std::size_t k = 0; k < reference.points(); ++k) {
    compare.add(reference.time_s[k], std::span<const double>(reference.positions_m.data() + 3 * n * k, 3 * n),
                {reference.force_n[3 * k], reference.force_n[3 * k + 1], reference.force_n[3 * k + 2]},
                reference.energy_j[k]);
  }
  return compare.result();
}

std::string describe_reference(const RunSpec& run, const ModelDescription& tissue) {
  const SettingDescription d = describe_setting(run.parameters, tissue);
  std::string text = d.family();
  if (d.tolerance) {
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%g", *d.tolerance);
    text += std::string(d.integrator == "ida" ? ", rtol " : ", tolerance ") + buffer;
  }
  return text + " @ " + step_label(run.step_s);
}

/// Runs `indices` of `runs` on `jobs` threads; rows in the order of `indices`.
std::vector<CompareRow> run_all(const std::vector<std::size_t>& indices, const std::vector<RunSpec>& runs,
                                const Scenario& scenario, const CompareOptions& options,
                                const ReferenceTrace& reference, const ModelDescription& tissue,
                                ProgressLine& progress) {
  std::vector<CompareRow> rows(indices.size());
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t k = next.fetch_add(1); k < indices.size(); k = next.fetch_add(1)) {
      const RunSpec& run = runs[indices[k]];
      progress.starting(run);
      try {
        rows[k] = make_row(run, run_measured(scenario, run, options.fmu_dir, &reference, nullptr), tissue);
      } catch (const std::exception& error) {  // never lose a row: run_measured catches the rest
        RunOutcome failed;
        failed.note = std::string("not run: ") + error.what();
        rows[k] = make_row(run, failed, tissue);
      }
      progress.finished();
    }
  };
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(options.jobs), indices.size());
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& thread : pool) thread.join();
  return rows;
}

}  // namespace

CompareReport run_compare(const CompareOptions& options, RunDistribution& distribution) {
  if (options.jobs < 1) throw ScenarioError("--jobs must be at least 1, got " + std::to_string(options.jobs));
  Scenario scenario = load_scenario(options.scenario_file);
  if (options.duration_s) {
    if (!(*options.duration_s > 0.0)) throw ScenarioError("--duration must be > 0 s");
    scenario.duration_s = *options.duration_s;
  }
  CompareSettingsList list = choose_settings(options);
  if (!options.steps_s.empty()) {
    list.steps_s = options.steps_s;
    list.steps_key = "--steps";
    for (CompareSetting& s : list.settings) s.steps_s.clear();
  }
  const std::filesystem::path tissue_fmu =
      scenario.tissue_fmu.empty() ? options.fmu_dir / "Tissue.fmu" : scenario.tissue_fmu;
  const ModelDescription tissue = tissue_description(tissue_fmu);
  std::string reference_note;
  const std::vector<RunSpec> runs = plan_runs(list, scenario, tissue, reference_note);
  keep_solver_libraries_on_the_calling_thread();  // before any thread starts

  const bool root = distribution.rank() == 0;
  const auto size = static_cast<std::size_t>(distribution.size());
  const auto rank = static_cast<std::size_t>(distribution.rank());
  std::vector<std::size_t> mine;  // round robin over the ranks, the reference (row 0) apart
  for (std::size_t i = 1; i < runs.size(); ++i) {
    if ((i - 1) % size == rank) mine.push_back(i);
  }
  // Rank 0 shows its own runs (the reference and its share).
  ProgressLine progress(root ? options.progress : nullptr, options.progress_in_place && size == 1,
                        mine.size() + (root ? 1 : 0),
                        size == 1 ? "compare: " : "compare (rank 0 of " + std::to_string(size) + "): ");

  // The reference on rank 0, its trace to every rank (or why it failed, so that no rank waits).
  ReferenceTrace reference;
  RunOutcome reference_outcome;
  std::string message;
  if (root) {
    progress.starting(runs[0]);
    reference_outcome = run_measured(scenario, runs[0], options.fmu_dir, nullptr, &reference);
    progress.finished();
    if (!reference_outcome.ran || reference_outcome.failures > 0 || reference.points() == 0) {
      message = "E" + (reference_outcome.note.empty() ? std::string("no communication point") : reference_outcome.note);
    } else {
      message = "R" + reference.to_bytes();
    }
  }
  distribution.broadcast(message);
  if (message.empty() || message.front() != 'R') {
    throw std::runtime_error("the reference run (" + describe_reference(runs[0], tissue) +
                             ") failed: " + (message.empty() ? std::string() : message.substr(1)));
  }
  if (!root) reference = ReferenceTrace::from_bytes(std::string_view(message).substr(1));
  message.clear();
  message.shrink_to_fit();

  const std::vector<CompareRow> my_rows = run_all(mine, runs, scenario, options, reference, tissue, progress);
  std::string text;
  for (std::size_t k = 0; k < mine.size(); ++k) text += std::to_string(mine[k]) + '\t' + csv_row(my_rows[k]) + '\n';
  const std::vector<std::string> texts = distribution.gather(text);
  progress.end();
  if (!root) return {};

  CompareReport report;
  report.scenario = scenario.name;
  report.processes = distribution.size();
  report.threads = options.jobs;
  report.reference = describe_reference(runs[0], tissue);
  if (!reference_note.empty()) report.notes.push_back(reference_note);
  std::vector<std::optional<CompareRow>> rows(runs.size());
  reference_outcome.errors = self_comparison(reference);
  rows[0] = make_row(runs[0], reference_outcome, tissue);
  for (const std::string& part : texts) {
    std::istringstream lines(part);
    for (std::string line; std::getline(lines, line);) {
      const std::size_t tab = line.find('\t');
      std::size_t index = 0;
      const auto [end, error] = std::from_chars(line.data(), line.data() + tab, index);
      if (tab == std::string::npos || error != std::errc() || index == 0 || index >= rows.size()) {
        throw std::runtime_error("compare: a gathered row is malformed: " + line);
      }
      rows[index] = parse_csv_row(std::string_view(line).substr(tab + 1));
    }
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!rows[i]) throw std::runtime_error("compare: no row came back for run " + std::to_string(i));
    report.rows.push_back(std::move(*rows[i]));
  }
  mark_pareto_front(report.rows);
  report.recommendations = recommend(report.rows);
  write_compare_outputs(options.output_dir, report);
  return report;
}

}  // namespace tissue::host
