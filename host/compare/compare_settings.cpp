// The settings of tissue-host compare (see compare_settings.hpp).
#include "compare/compare_settings.hpp"

#include "compare/compare_table.hpp"
#include "scenario/parameter_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

namespace tissue::host {
namespace {

ParameterSetting text(const char* name, const char* value) { return {name, std::string(value)}; }
ParameterSetting number(const char* name, double value) { return {name, value}; }
ParameterSetting integer(const char* name, std::int64_t value) { return {name, value}; }

CompareSetting setting(std::string name, std::vector<ParameterSetting> parameters) {
  return {std::move(name), std::move(parameters), {}};
}

bool divides(double communication_step_s, double step_s) {
  if (!(step_s > 0.0)) return false;
  const double n = std::round(communication_step_s / step_s);
  return n >= 1.0 && std::abs(n * step_s - communication_step_s) <= 1e-9 * communication_step_s;
}

std::string seconds_text(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

const ParameterSetting* find_parameter(const std::vector<ParameterSetting>& parameters, std::string_view name) {
  const auto it =
      std::find_if(parameters.begin(), parameters.end(), [&](const ParameterSetting& p) { return p.name == name; });
  return it == parameters.end() ? nullptr : &*it;
}

// --- reading [compare] ---

class TableReader {
 public:
  explicit TableReader(std::string origin) : m_origin(std::move(origin)) {}
  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    throw ScenarioError(m_origin + ": " + key + ": " + why);
  }
  void only(const toml::table& table, const std::string& where, std::initializer_list<std::string_view> keys) const {
    for (const auto& [key, value] : table) {
      if (std::find(keys.begin(), keys.end(), key.str()) == keys.end()) {
        fail(where + "." + std::string(key.str()), "unknown key");
      }
    }
  }
  std::vector<double> steps(const toml::node& node, const std::string& key) const {
    const toml::array* array = node.as_array();
    if (array == nullptr || array->empty()) fail(key, "must be a non-empty array of internal steps [s]");
    std::vector<double> values;
    for (const toml::node& element : *array) {
      double value = 0.0;
      if (const auto* f = element.as_floating_point()) {
        value = f->get();
      } else if (const auto* i = element.as_integer()) {
        value = static_cast<double>(i->get());
      } else {
        fail(key, "must hold numbers (seconds)");
      }
      if (!(value > 0.0) || !std::isfinite(value)) fail(key, "steps must be > 0 s, got " + seconds_text(value));
      values.push_back(value);
    }
    return values;
  }
  std::vector<ParameterSetting> parameters(const toml::node& node, const std::string& key) const {
    const toml::table* table = node.as_table();
    if (table == nullptr) fail(key, "must be a table of Tissue FMU parameters by name");
    return read_parameter_table(*table, key, m_origin);
  }
  [[nodiscard]] const std::string& origin() const { return m_origin; }

 private:
  std::string m_origin;
};

CompareSetting read_setting(const TableReader& r, const toml::node& node, const std::string& key, bool needs_name) {
  const toml::table* table = node.as_table();
  if (table == nullptr) r.fail(key, "must be a table { name, parameters, steps }");
  r.only(*table, key,
         needs_name ? std::initializer_list<std::string_view>{"name", "parameters", "steps"}
                    : std::initializer_list<std::string_view>{"parameters", "step"});
  CompareSetting s;
  if (needs_name) {
    const toml::node* name = table->get("name");
    if (name == nullptr || name->as_string() == nullptr || name->as_string()->get().empty()) {
      r.fail(key + ".name", "a setting needs a name (a non-empty string)");
    }
    s.name = name->as_string()->get();
  } else {
    s.name = "reference";
  }
  if (const toml::node* p = table->get("parameters")) s.parameters = r.parameters(*p, key + ".parameters");
  if (const toml::node* steps = table->get("steps")) s.steps_s = r.steps(*steps, key + ".steps");
  if (const toml::node* step = table->get("step")) {
    toml::array one;
    if (const auto* f = step->as_floating_point()) one.push_back(f->get());
    if (const auto* i = step->as_integer()) one.push_back(i->get());
    if (one.empty()) r.fail(key + ".step", "must be a number (seconds)");
    s.steps_s = r.steps(one, key + ".step");
  }
  return s;
}

// --- checking against the FMU ---

/// Why the FMU cannot take this parameter (empty if it can); enumeration items by name.
std::string unusable(const ParameterSetting& p, const ModelDescription& tissue) {
  const ModelVariable* variable = tissue.find_variable(p.name);
  if (variable == nullptr) return "this Tissue.fmu has no variable of this name";
  if (variable->causality != "parameter" && variable->causality != "structuralParameter") {
    return "is a " + variable->causality + ", not a parameter";
  }
  if (const auto* item = std::get_if<std::string>(&p.value); item != nullptr && variable->type == "Enumeration") {
    const TypeDefinition* type = tissue.find_type(variable->declared_type);
    const bool known = type != nullptr && std::any_of(type->items.begin(), type->items.end(),
                                                      [&](const EnumerationItem& e) { return e.name == *item; });
    if (!known) return "\"" + *item + "\" is not an item of " + variable->declared_type;
  }
  return {};
}

/// The first problem of a setting with this FMU ("key: why"), or empty.
std::string first_problem(const CompareSetting& s, const std::string& where, const ModelDescription& tissue) {
  for (const ParameterSetting& p : s.parameters) {
    const std::string why = unusable(p, tissue);
    if (!why.empty()) return where + ".parameters." + p.name + ": " + why;
  }
  return {};
}

/// A built-in setting on an FMU from before IDA: backward Euler is then all it integrates with, so
/// asking for it is no reason to skip the setting.
CompareSetting without_implicit_backward_euler(CompareSetting s, const ModelDescription& tissue) {
  if (tissue.find_variable("integrator.method") != nullptr) return s;
  std::erase_if(s.parameters, [](const ParameterSetting& p) {
    const auto* item = std::get_if<std::string>(&p.value);
    const auto* number = std::get_if<std::int64_t>(&p.value);
    return p.name == "integrator.method" &&
           ((item != nullptr && *item == "backwardEuler") || (number != nullptr && *number == 1));
  });
  return s;
}

RunSpec make_run(std::size_t index, const CompareSetting& s, bool is_reference, double step_s) {
  RunSpec run;
  run.index = index;
  run.setting = s.name;
  run.is_reference = is_reference;
  run.step_s = step_s;
  run.parameters = s.parameters;
  run.parameters.push_back({"stepSize", step_s});
  return run;
}

// --- describing ---

std::string enumeration_item(const ModelVariable& variable, std::int64_t value, const ModelDescription& tissue) {
  if (const TypeDefinition* type = tissue.find_type(variable.declared_type)) {
    for (const EnumerationItem& item : type->items) {
      if (item.value == value) return item.name;
    }
  }
  return std::to_string(value);
}

/// The value a run gives `name` as text (enumerations as item names): its own, else the FMU's start.
std::optional<std::string> value_text(const std::vector<ParameterSetting>& parameters, std::string_view name,
                                      const ModelDescription& tissue) {
  const ModelVariable* variable = tissue.find_variable(name);
  if (const ParameterSetting* p = find_parameter(parameters, name)) {
    if (const auto* s = std::get_if<std::string>(&p->value)) return *s;
    if (const auto* i = std::get_if<std::int64_t>(&p->value)) {
      return variable != nullptr && variable->type == "Enumeration" ? enumeration_item(*variable, *i, tissue)
                                                                    : std::to_string(*i);
    }
    if (const auto* d = std::get_if<double>(&p->value)) {
      char buffer[32];
      const auto [end, error] = std::to_chars(buffer, buffer + sizeof(buffer), *d);
      return std::string(buffer, error == std::errc() ? end : buffer);
    }
    return std::nullopt;
  }
  if (variable == nullptr || !variable->start) return std::nullopt;
  if (variable->type == "Enumeration") {
    std::int64_t value = 0;
    const std::string& start = *variable->start;
    if (std::from_chars(start.data(), start.data() + start.size(), value).ec == std::errc()) {
      return enumeration_item(*variable, value, tissue);
    }
  }
  return *variable->start;
}

std::optional<double> value_number(const std::vector<ParameterSetting>& parameters, std::string_view name,
                                   const ModelDescription& tissue) {
  const std::optional<std::string> text_value = value_text(parameters, name, tissue);
  if (!text_value) return std::nullopt;
  double value = 0.0;
  const char* begin = text_value->data();
  const char* end = begin + text_value->size();
  const auto [stop, error] = std::from_chars(begin, end, value);
  if (error != std::errc() || stop != end) return std::nullopt;
  return value;
}

}  // namespace

std::string SettingDescription::family() const { return setting_family(integrator, linear_solver, material_model); }

CompareSettingsList default_settings() {
  CompareSettingsList list;
  const auto be = [](std::vector<ParameterSetting> rest) {
    rest.insert(rest.begin(), text("integrator.method", "backwardEuler"));
    return rest;
  };
  const auto ida = [](const char* solver, double relative_tolerance) {
    return std::vector<ParameterSetting>{text("integrator.method", "ida"), text("integrator.idaLinearSolver", solver),
                                         number("integrator.idaRelativeTolerance", relative_tolerance)};
  };
  list.settings = {
      // The real-time default (issue 40: the two-level preconditioner, capped at 10 iterations, one
      // Newton correction, each step linearized at its predicted end), the same linearized at the start
      // (the dissertation's step, the default before issue 41), the default before issue 40 (Jacobi PCG
      // capped at 10, up to 5 corrections),
      // Jacobi PCG converged, CG on the lagged Cholesky factor (warm-started, converged), the
      // two-level preconditioner converged from the warm start (the fastest converged step: docs/BENCHMARKS.md).
      setting("be-pcgTwoLevel-tol1e-3-cap10",
              be({text("integrator.linearSolver", "pcgTwoLevel"), number("integrator.pcgTolerance", 1e-3),
                  integer("integrator.pcgMaxIterations", 10), integer("integrator.newtonMaxIterations", 1)})),
      setting("be-pcgTwoLevel-tol1e-3-cap10-atStart",
              be({text("integrator.linearSolver", "pcgTwoLevel"), number("integrator.pcgTolerance", 1e-3),
                  integer("integrator.pcgMaxIterations", 10), integer("integrator.newtonMaxIterations", 1),
                  ParameterSetting{"integrator.linearizeAtPredictedEnd", false}})),
      setting("be-pcg-tol1e-3-cap10",
              be({text("integrator.linearSolver", "pcg"), number("integrator.pcgTolerance", 1e-3),
                  integer("integrator.pcgMaxIterations", 10), integer("integrator.newtonMaxIterations", 5)})),
      setting("be-pcg-tol1e-6-cap1000",
              be({text("integrator.linearSolver", "pcg"), number("integrator.pcgTolerance", 1e-6),
                  integer("integrator.pcgMaxIterations", 1000)})),
      setting("be-pcgCholesky-tol1e-5-cap25",
              be({text("integrator.linearSolver", "pcgCholesky"), number("integrator.pcgTolerance", 1e-5),
                  integer("integrator.pcgMaxIterations", 25), ParameterSetting{"integrator.warmStart", true}})),
      setting("be-pcgTwoLevel-tol1e-6-warm",
              be({text("integrator.linearSolver", "pcgTwoLevel"), number("integrator.pcgTolerance", 1e-6),
                  integer("integrator.pcgMaxIterations", 1000), ParameterSetting{"integrator.warmStart", true}})),
      setting("be-cholmod", be({text("integrator.linearSolver", "cholmod")})),
      setting("ida-klu-rtol1e-3", ida("klu", 1e-3)),
      setting("ida-klu-rtol1e-5", ida("klu", 1e-5)),
      setting("ida-krylov-rtol1e-3", ida("krylov", 1e-3)),
  };
  list.reference =
      setting("reference", {text("integrator.method", "ida"), text("integrator.idaLinearSolver", "klu"),
                            number("integrator.idaRelativeTolerance", 1e-7),
                            number("integrator.idaAbsoluteTolerance", 1e-10), number("integrator.idaMaxStep", 1e-3)});
  return list;
}

std::vector<double> default_steps(double communication_step_s) {
  std::vector<double> steps;
  if (communication_step_s > 1e-3 && divides(communication_step_s, 1e-3)) steps.push_back(1e-3);
  steps.push_back(communication_step_s);
  return steps;
}

std::optional<CompareSettingsList> read_compare_table(const std::filesystem::path& file) {
  toml::table root;
  try {
    root = toml::parse_file(file.string());
  } catch (const toml::parse_error& error) {
    std::ostringstream message;
    message << file.string() << ":" << error.source().begin.line << ": " << error.description();
    throw ScenarioError(message.str());
  }
  const toml::node* node = root.get("compare");
  if (node == nullptr) return std::nullopt;
  const TableReader r(file.string());
  const toml::table* table = node->as_table();
  if (table == nullptr) r.fail("compare", "must be a table");
  r.only(*table, "compare", {"steps", "settings", "reference"});
  CompareSettingsList list = default_settings();
  list.origin = file.string();
  if (const toml::node* steps = table->get("steps")) list.steps_s = r.steps(*steps, "compare.steps");
  if (const toml::node* settings = table->get("settings")) {
    const toml::array* array = settings->as_array();
    if (array == nullptr || array->empty()) r.fail("compare.settings", "must be a non-empty array of tables");
    list.settings.clear();
    list.built_in = false;
    for (std::size_t k = 0; k < array->size(); ++k) {
      list.settings.push_back(read_setting(r, *array->get(k), "compare.settings[" + std::to_string(k) + "]", true));
    }
  }
  if (const toml::node* reference = table->get("reference")) {
    list.reference = read_setting(r, *reference, "compare.reference", false);
    list.built_in_reference = false;
  }
  return list;
}

std::vector<RunSpec> plan_runs(const CompareSettingsList& list, const Scenario& scenario,
                               const ModelDescription& tissue, std::string& note) {
  const std::string& origin = list.origin;
  const double communication_step_s = scenario.tissue_step_s;
  const auto fail = [&](const std::string& key, const std::string& why) -> void {
    throw ScenarioError(origin + ": " + key + ": " + why);
  };
  const auto check_steps = [&](const std::vector<double>& steps, const std::string& key) {
    for (const double step : steps) {
      if (!divides(communication_step_s, step)) {
        fail(key, seconds_text(step) + " s does not divide the communication step " +
                      seconds_text(communication_step_s) + " s (tissue.communication_step of " +
                      scenario.file.string() + "); use a step of which it is a whole multiple");
      }
    }
  };
  const std::vector<double> steps = list.steps_s.empty() ? default_steps(communication_step_s) : list.steps_s;
  check_steps(steps, list.steps_key);
  if (list.settings.empty()) fail("compare.settings", "no settings to compare");

  std::set<std::string> names{"reference"};
  double smallest_step_s = steps.front();
  for (std::size_t k = 0; k < list.settings.size(); ++k) {
    const CompareSetting& s = list.settings[k];
    const std::string where = "compare.settings[" + std::to_string(k) + "] (" + s.name + ")";
    if (!names.insert(s.name).second) fail(where + ".name", "\"" + s.name + "\" is used twice (or is \"reference\")");
    if (find_parameter(s.parameters, "stepSize") != nullptr) {
      fail(where + ".parameters.stepSize", "the internal step comes from steps, not from the parameters");
    }
    check_steps(s.steps_s, where + ".steps");
    for (const double step : s.steps_s.empty() ? steps : s.steps_s) smallest_step_s = std::min(smallest_step_s, step);
    if (!list.built_in) {
      const std::string problem = first_problem(s, where, tissue);
      if (!problem.empty()) throw ScenarioError(origin + ": " + problem);
    }
  }

  // The reference: as given, or the built-in one; a built-in reference this FMU cannot run (no
  // IDA yet) falls back to the tightest backward Euler there is, CHOLMOD at the smallest step.
  CompareSetting reference = list.reference;
  check_steps(reference.steps_s, "compare.reference.step");
  if (find_parameter(reference.parameters, "stepSize") != nullptr) {
    fail("compare.reference.parameters.stepSize", "the internal step is compare.reference.step");
  }
  const double reference_step_s = reference.steps_s.empty() ? smallest_step_s : reference.steps_s.front();
  note.clear();
  const std::string reference_problem = first_problem(reference, "compare.reference", tissue);
  if (!reference_problem.empty()) {
    if (!list.built_in_reference) throw ScenarioError(origin + ": " + reference_problem);
    reference.parameters = {text("integrator.method", "backwardEuler"), text("integrator.linearSolver", "cholmod")};
    reference = without_implicit_backward_euler(reference, tissue);
    note = "reference: " + reference_problem + "; using backward Euler with CHOLMOD at " +
           step_label(reference_step_s) + " instead";
  }

  std::vector<RunSpec> runs;
  runs.push_back(make_run(0, reference, true, reference_step_s));
  for (std::size_t k = 0; k < list.settings.size(); ++k) {
    const CompareSetting s =
        list.built_in ? without_implicit_backward_euler(list.settings[k], tissue) : list.settings[k];
    const std::string problem = first_problem(s, "settings." + s.name, tissue);
    for (const double step : s.steps_s.empty() ? steps : s.steps_s) {
      RunSpec run = make_run(runs.size(), s, false, step);
      if (!problem.empty()) run.skipped = "not run: " + problem;
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

SettingDescription describe_setting(const std::vector<ParameterSetting>& parameters, const ModelDescription& tissue) {
  SettingDescription d;
  d.integrator = value_text(parameters, "integrator.method", tissue).value_or("backwardEuler");
  d.material_model = value_text(parameters, "material.model", tissue).value_or(DEFAULT_MATERIAL_MODEL);
  if (d.integrator == "ida") {
    d.linear_solver = value_text(parameters, "integrator.idaLinearSolver", tissue).value_or("klu");
    d.tolerance = value_number(parameters, "integrator.idaRelativeTolerance", tissue);
  } else {
    d.linear_solver = value_text(parameters, "integrator.linearSolver", tissue).value_or("pcg");
    if (d.linear_solver != "cholmod") {  // every other backward-Euler solver is CG with a tolerance and a cap
      d.tolerance = value_number(parameters, "integrator.pcgTolerance", tissue);
      if (const std::optional<double> cap = value_number(parameters, "integrator.pcgMaxIterations", tissue)) {
        d.iteration_cap = static_cast<std::int64_t>(*cap);
      }
    }
  }
  return d;
}

std::string step_label(double step_s) { return seconds_text(step_s * 1e3) + " ms"; }

}  // namespace tissue::host
