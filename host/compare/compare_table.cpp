// compare.csv (see compare_table.hpp).
#include "compare/compare_table.hpp"

#include "output/session_log.hpp"

#include <charconv>
#include <fstream>
#include <stdexcept>
#include <type_traits>

namespace tissue::host {
namespace {

constexpr std::size_t COLUMNS = 16;

template <class T>
void append_optional(std::string& line, const std::optional<T>& value) {
  line += ',';
  if (!value) return;
  if constexpr (std::is_floating_point_v<T>) {
    append_number(line, *value);
  } else {
    line += std::to_string(*value);
  }
}

std::string quoted(const std::string& text) {
  std::string clean;
  for (const char c : text) clean += (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
  while (!clean.empty() && clean.back() == ' ') clean.pop_back();
  if (clean.find_first_of(",\"") == std::string::npos) return clean;
  std::string out = "\"";
  for (const char c : clean) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::vector<std::string> split_fields(std::string_view line) {
  std::vector<std::string> fields(1);
  bool in_quotes = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_quotes) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        in_quotes = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      in_quotes = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

template <class T>
T parse_number(const std::string& field, const char* column) {
  T value{};
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
  if (error != std::errc() || end != field.data() + field.size()) {
    throw std::runtime_error(std::string("compare row: column ") + column + ": not a number: \"" + field + "\"");
  }
  return value;
}

template <class T>
std::optional<T> parse_optional(const std::string& field, const char* column) {
  if (field.empty()) return std::nullopt;
  return parse_number<T>(field, column);
}

}  // namespace

std::string setting_family(const std::string& integrator, const std::string& linear_solver,
                           const std::string& material_model) {
  std::string family = integrator + "/" + linear_solver;
  if (!material_model.empty() && material_model != DEFAULT_MATERIAL_MODEL) family += "/" + material_model;
  return family;
}

bool CompareRow::comparable() const { return rms_error_m && cpu_s_per_sim_s && failures == 0; }

std::string csv_header() {
  return "setting,integrator,linear_solver,material_model,tolerance,iteration_cap,internal_step_s,cpu_s_per_sim_s,"
         "rms_error_m,max_error_m,force_error_n,energy_drift_j,iterations,failures,pareto,note";
}

std::string csv_row(const CompareRow& row) {
  std::string line = quoted(row.setting) + ',' + quoted(row.integrator) + ',' + quoted(row.linear_solver) + ',' +
                     quoted(row.material_model);
  append_optional(line, row.tolerance);
  append_optional(line, row.iteration_cap);
  append_optional(line, std::optional<double>(row.internal_step_s));
  append_optional(line, row.cpu_s_per_sim_s);
  append_optional(line, row.rms_error_m);
  append_optional(line, row.max_error_m);
  append_optional(line, row.force_error_n);
  append_optional(line, row.energy_drift_j);
  append_optional(line, row.iterations);
  line += ',' + std::to_string(row.failures);
  line += row.pareto ? ",1," : ",0,";
  line += quoted(row.note);
  return line;
}

CompareRow parse_csv_row(std::string_view line) {
  const std::vector<std::string> f = split_fields(line);
  if (f.size() != COLUMNS) {
    throw std::runtime_error("compare row: " + std::to_string(f.size()) + " fields, expected " +
                             std::to_string(COLUMNS));
  }
  CompareRow row;
  row.setting = f[0];
  row.integrator = f[1];
  row.linear_solver = f[2];
  row.material_model = f[3];
  row.tolerance = parse_optional<double>(f[4], "tolerance");
  row.iteration_cap = parse_optional<std::int64_t>(f[5], "iteration_cap");
  row.internal_step_s = parse_number<double>(f[6], "internal_step_s");
  row.cpu_s_per_sim_s = parse_optional<double>(f[7], "cpu_s_per_sim_s");
  row.rms_error_m = parse_optional<double>(f[8], "rms_error_m");
  row.max_error_m = parse_optional<double>(f[9], "max_error_m");
  row.force_error_n = parse_optional<double>(f[10], "force_error_n");
  row.energy_drift_j = parse_optional<double>(f[11], "energy_drift_j");
  row.iterations = parse_optional<std::uint64_t>(f[12], "iterations");
  row.failures = parse_number<std::uint64_t>(f[13], "failures");
  row.pareto = f[14] == "1";
  row.note = f[15];
  return row;
}

void write_csv(const std::filesystem::path& file, const std::vector<CompareRow>& rows) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out << csv_header() << '\n';
  for (const CompareRow& row : rows) out << csv_row(row) << '\n';
  if (!out) throw std::runtime_error(file.string() + ": cannot be written");
}

}  // namespace tissue::host
