// The outputs of tissue-host compare (see compare_report.hpp).
#include "compare/compare_report.hpp"

#include "compare/compare_metrics.hpp"
#include "compare/compare_settings.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <stdexcept>

namespace tissue::host {
namespace {

std::string label(const CompareRow& row) { return row.setting + " @ " + step_label(row.internal_step_s); }

std::string short_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

/// Lines of at most `width` characters, broken after ", " where possible; continuations indented.
std::vector<std::string> wrap(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::string rest = text;
  while (rest.size() > width) {
    const std::size_t comma = rest.rfind(", ", width - 1);
    const std::size_t cut = comma == std::string::npos || comma < 3 ? width : comma + 1;  // keep the comma
    lines.push_back(rest.substr(0, cut));
    const std::size_t next = rest.find_first_not_of(' ', cut);
    rest = std::string("  ").append(next == std::string::npos ? std::string() : rest.substr(next));
  }
  lines.push_back(rest);
  return lines;
}

template <class T>
nlohmann::ordered_json json_value(const std::optional<T>& value) {
  return value ? nlohmann::ordered_json(*value) : nlohmann::ordered_json(nullptr);
}

// compare.json. nlohmann::json writes non-finite numbers (a metric of a failed run) as null.
std::string json_document(const CompareReport& report) {
  nlohmann::ordered_json j;
  j["scenario"] = report.scenario;
  j["reference"] = report.reference;
  j["notes"] = report.notes;
  nlohmann::ordered_json& rows = j["rows"] = nlohmann::ordered_json::array();
  for (const CompareRow& r : report.rows) {
    rows.push_back({{"setting", r.setting},
                    {"integrator", r.integrator},
                    {"linear_solver", r.linear_solver},
                    {"material_model", r.material_model},
                    {"tolerance", json_value(r.tolerance)},
                    {"iteration_cap", json_value(r.iteration_cap)},
                    {"internal_step_s", r.internal_step_s},
                    {"cpu_s_per_sim_s", json_value(r.cpu_s_per_sim_s)},
                    {"rms_error_m", json_value(r.rms_error_m)},
                    {"max_error_m", json_value(r.max_error_m)},
                    {"force_error_n", json_value(r.force_error_n)},
                    {"energy_drift_j", json_value(r.energy_drift_j)},
                    {"iterations", json_value(r.iterations)},
                    {"failures", r.failures},
                    {"pareto", r.pareto},
                    {"note", r.note}});
  }
  nlohmann::ordered_json& recommendations = j["recommendations"] = nlohmann::ordered_json::array();
  for (const Recommendation& r : report.recommendations) {
    recommendations.push_back(
        {{"use", r.use.name},
         {"setting", r.row ? nlohmann::ordered_json(report.rows[*r.row].setting) : nlohmann::ordered_json(nullptr)},
         {"internal_step_s",
          r.row ? nlohmann::ordered_json(report.rows[*r.row].internal_step_s) : nlohmann::ordered_json(nullptr)},
         {"text", r.text}});
  }
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

}  // namespace

void mark_pareto_front(std::vector<CompareRow>& rows) {
  std::vector<double> cost(rows.size(), 0.0), error(rows.size(), 0.0);
  std::vector<bool> eligible(rows.size(), false);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    eligible[i] = rows[i].comparable() && !rows[i].is_reference();
    if (eligible[i]) {
      cost[i] = *rows[i].cpu_s_per_sim_s;
      error[i] = *rows[i].rms_error_m;
    }
  }
  const std::vector<bool> front = pareto_front(cost, error, eligible);
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i].pareto = front[i];
}

LogLogPlot compare_plot(const CompareReport& report, std::vector<std::string>& omitted) {
  LogLogPlot plot;
  plot.width = COMPARE_PLOT_WIDTH;
  plot.height = COMPARE_PLOT_HEIGHT;
  plot.title = report.scenario + ": error against cost";
  plot.x_title = "cost: CPU s of Tissue doStep per simulated s";
  plot.y_title = "RMS surface error (m)";
  std::string zero, missing;
  for (const CompareRow& row : report.rows) {
    const bool has = row.rms_error_m && row.cpu_s_per_sim_s && row.failures == 0 &&
                     std::isfinite(*row.rms_error_m) && std::isfinite(*row.cpu_s_per_sim_s);
    if (has && *row.rms_error_m > 0.0 && *row.cpu_s_per_sim_s > 0.0) {
      const auto family = std::find(plot.series.begin(), plot.series.end(), row.family());
      const std::size_t series = static_cast<std::size_t>(family - plot.series.begin());
      if (family == plot.series.end()) plot.series.push_back(row.family());
      if (row.pareto) plot.front.push_back(plot.points.size());
      plot.points.push_back({*row.cpu_s_per_sim_s, *row.rms_error_m, series});
    } else if (has) {
      zero += (zero.empty() ? "" : ", ") + label(row);
    } else {
      missing += (missing.empty() ? "" : ", ") + label(row);
    }
  }
  omitted.clear();
  if (!zero.empty()) omitted.push_back("not shown, zero error (no place on a log axis): " + zero);
  if (!missing.empty()) omitted.push_back("not shown, no error or cost (not run, failed, not finite or not compared): " + missing);
  plot.notes.push_back("reference: " + report.reference);
  for (const std::string& note : report.notes) plot.notes.push_back(note);
  for (const std::string& line : omitted) plot.notes.push_back(line);
  const std::size_t width = note_characters(plot.width);
  std::vector<std::string> wrapped;
  for (const std::string& note : plot.notes) {
    for (std::string& line : wrap(note, width)) wrapped.push_back(std::move(line));
  }
  if (plot.points.empty()) wrapped.insert(wrapped.begin(), "no row has both an error and a cost to plot");
  constexpr std::size_t MOST_NOTE_LINES = 12;  // the image keeps its size: see compare.csv for the rest
  if (wrapped.size() > MOST_NOTE_LINES) {
    wrapped.resize(MOST_NOTE_LINES);
    wrapped.back() = "... (more in compare.csv and compare.json)";
  }
  plot.notes = std::move(wrapped);
  return plot;
}

void write_compare_outputs(const std::filesystem::path& dir, const CompareReport& report) {
  std::filesystem::create_directories(dir);
  write_csv(dir / "compare.csv", report.rows);
  std::vector<std::string> omitted;
  write_png(dir / "compare.png", render_log_log_plot(compare_plot(report, omitted)));
  {
    std::ofstream out(dir / "recommendation.txt", std::ios::binary | std::ios::trunc);
    out << "Scenario " << report.scenario << "; reference " << report.reference << "\n";
    for (const Recommendation& r : report.recommendations) out << r.text << "\n";
    for (const std::string& note : report.notes) out << "note: " << note << "\n";
    if (!out) throw std::runtime_error((dir / "recommendation.txt").string() + ": cannot be written");
  }
  std::ofstream json(dir / "compare.json", std::ios::binary | std::ios::trunc);
  json << json_document(report);
  if (!json) throw std::runtime_error((dir / "compare.json").string() + ": cannot be written");
}

void print_compare(std::ostream& out, const CompareReport& report, const std::filesystem::path& dir) {
  out << "compare " << report.scenario << ": " << report.rows.size() << " runs on " << report.processes
      << (report.processes == 1 ? " process x " : " processes x ") << report.threads
      << (report.threads == 1 ? " thread" : " threads") << ", against the reference (" << report.reference << ")\n";
  for (const std::string& note : report.notes) out << "  note: " << note << "\n";
  char line[256];
  std::snprintf(line, sizeof(line), "  %-28s %8s %12s %12s %12s %8s\n", "setting", "step", "CPU s/sim s", "RMS err [m]",
                "force [N]", "pareto");
  out << line;
  for (const CompareRow& r : report.rows) {
    const auto field = [](const std::optional<double>& v) { return v ? short_number(*v) : std::string("-"); };
    std::snprintf(line, sizeof(line), "  %-28s %8s %12s %12s %12s %8s\n", r.setting.c_str(),
                  step_label(r.internal_step_s).c_str(), field(r.cpu_s_per_sim_s).c_str(), field(r.rms_error_m).c_str(),
                  field(r.force_error_n).c_str(),
                  r.pareto ? "*" : (r.failures > 0 ? "failed" : (r.rms_error_m ? "" : "-")));
    out << line;
  }
  for (const Recommendation& r : report.recommendations) out << "  " << r.text << "\n";
  out << "  outputs in " << dir.string() << ": compare.csv, compare.png, recommendation.txt, compare.json\n";
}

}  // namespace tissue::host
