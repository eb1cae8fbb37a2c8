// model_description.cpp - parsing and checking of modelDescription.xml with pugixml.
#include "importer/model_description.hpp"

#include "importer/fmu_archive.hpp"
#include "importer/fmu_error.hpp"

#include <pugixml.hpp>

#include <algorithm>
#include <array>
#include <charconv>
#include <limits>
#include <system_error>
#include <utility>

namespace tissue::host {
namespace {

/// Element names of the variable types of FMI 3.0 (section 2.4.7).
constexpr std::array<std::string_view, 15> VARIABLE_TYPES = {"Float32", "Float64", "Int8",        "UInt8",  "Int16",
                                                             "UInt16",  "Int32",   "UInt32",      "Int64",  "UInt64",
                                                             "Boolean", "String",  "Enumeration", "Binary", "Clock"};

constexpr std::array<std::string_view, 7> CAUSALITIES = {
    "parameter", "calculatedParameter", "structuralParameter", "input", "output", "local", "independent"};

constexpr std::array<std::string_view, 5> VARIABILITIES = {"constant", "fixed", "tunable", "discrete", "continuous"};

constexpr std::array<std::string_view, 3> INITIALS = {"exact", "approx", "calculated"};

template <std::size_t N>
bool contains(const std::array<std::string_view, N>& list, std::string_view value) {
  return std::find(list.begin(), list.end(), value) != list.end();
}

bool is_float_type(std::string_view type) { return type == "Float32" || type == "Float64"; }

/// "variable 'x'" or "variable #3" when the name is not known yet, for error messages.
std::string variable_label(const ModelVariable& variable, std::size_t index) {
  if (!variable.name.empty()) {
    return "variable '" + variable.name + "'";
  }
  return "variable #" + std::to_string(index + 1) + " (<" + variable.type + ">)";
}

/// Parses a whole attribute as an integer of type T; throws FmuError with @p context.
template <typename T>
T parse_integer(std::string_view text, const std::string& context) {
  T value{};
  const char* first = text.data();
  const char* last = text.data() + text.size();
  if (!text.empty() && text.front() == '+') {
    ++first;
  }
  const auto [end, error] = std::from_chars(first, last, value);
  if (error != std::errc() || end != last || first == last) {
    throw FmuError("model description: " + context + ": '" + std::string(text) + "' is not a valid integer");
  }
  return value;
}

double parse_double(std::string_view text, const std::string& context) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) {
    throw FmuError("model description: " + context + ": '" + std::string(text) + "' is not a valid number");
  }
  return value;
}

/// xs:boolean attribute with a default when absent.
bool parse_bool(const pugi::xml_node& node, const char* attribute, bool fallback, const std::string& context) {
  const pugi::xml_attribute found = node.attribute(attribute);
  if (!found) {
    return fallback;
  }
  const std::string_view text = found.value();
  if (text == "true" || text == "1") {
    return true;
  }
  if (text == "false" || text == "0") {
    return false;
  }
  throw FmuError("model description: " + context + " attribute " + attribute + "='" + std::string(text) +
                 "' is not a boolean");
}

std::optional<double> optional_double(const pugi::xml_node& node, const char* attribute, const std::string& context) {
  const pugi::xml_attribute found = node.attribute(attribute);
  if (!found) {
    return std::nullopt;
  }
  return parse_double(found.value(), context + " attribute " + attribute);
}

std::optional<std::string> optional_text(const pugi::xml_node& node, const char* attribute) {
  const pugi::xml_attribute found = node.attribute(attribute);
  if (!found) {
    return std::nullopt;
  }
  return std::string(found.value());
}

CoSimulationCapabilities parse_co_simulation(const pugi::xml_node& node) {
  const std::string context = "<CoSimulation>";
  CoSimulationCapabilities caps;
  caps.model_identifier = node.attribute("modelIdentifier").value();
  if (caps.model_identifier.empty()) {
    throw FmuError("model description: <CoSimulation> has no modelIdentifier");
  }
  caps.needs_execution_tool = parse_bool(node, "needsExecutionTool", false, context);
  caps.can_be_instantiated_only_once_per_process =
      parse_bool(node, "canBeInstantiatedOnlyOncePerProcess", false, context);
  caps.can_get_and_set_fmu_state = parse_bool(node, "canGetAndSetFMUState", false, context);
  caps.can_serialize_fmu_state = parse_bool(node, "canSerializeFMUState", false, context);
  caps.provides_directional_derivatives = parse_bool(node, "providesDirectionalDerivatives", false, context);
  caps.provides_adjoint_derivatives = parse_bool(node, "providesAdjointDerivatives", false, context);
  caps.provides_per_element_dependencies = parse_bool(node, "providesPerElementDependencies", false, context);
  caps.can_handle_variable_communication_step_size =
      parse_bool(node, "canHandleVariableCommunicationStepSize", false, context);
  caps.provides_intermediate_update = parse_bool(node, "providesIntermediateUpdate", false, context);
  caps.might_return_early_from_do_step = parse_bool(node, "mightReturnEarlyFromDoStep", false, context);
  caps.can_return_early_after_intermediate_update =
      parse_bool(node, "canReturnEarlyAfterIntermediateUpdate", false, context);
  caps.has_event_mode = parse_bool(node, "hasEventMode", false, context);
  caps.provides_evaluate_discrete_states = parse_bool(node, "providesEvaluateDiscreteStates", false, context);
  if (const pugi::xml_attribute order = node.attribute("maxOutputDerivativeOrder")) {
    caps.max_output_derivative_order =
        parse_integer<std::uint32_t>(order.value(), context + " attribute maxOutputDerivativeOrder");
  }
  caps.fixed_internal_step_size_s = optional_double(node, "fixedInternalStepSize", context);
  if (const pugi::xml_attribute smoothness = node.attribute("recommendedIntermediateInputSmoothness")) {
    caps.recommended_intermediate_input_smoothness =
        parse_integer<std::int32_t>(smoothness.value(), context + " attribute recommendedIntermediateInputSmoothness");
  }
  return caps;
}

std::vector<TypeDefinition> parse_type_definitions(const pugi::xml_node& node) {
  std::vector<TypeDefinition> types;
  for (const pugi::xml_node& child : node.children()) {
    if (child.type() != pugi::node_element) {
      continue;
    }
    TypeDefinition type;
    type.kind = child.name();
    type.name = child.attribute("name").value();
    type.description = child.attribute("description").value();
    type.unit = child.attribute("unit").value();
    const std::string context = "<" + type.kind + " name=\"" + type.name + "\">";
    if (type.name.empty()) {
      throw FmuError("model description: a <" + type.kind + "> in <TypeDefinitions> has no name");
    }
    if (std::any_of(types.begin(), types.end(), [&](const TypeDefinition& t) { return t.name == type.name; })) {
      throw FmuError("model description: type definition '" + type.name + "' is defined twice");
    }
    if (type.kind == "EnumerationType") {
      for (const pugi::xml_node& item : child.children("Item")) {
        EnumerationItem parsed;
        parsed.name = item.attribute("name").value();
        parsed.description = item.attribute("description").value();
        const pugi::xml_attribute value = item.attribute("value");
        if (parsed.name.empty() || !value) {
          throw FmuError("model description: an <Item> of " + context + " lacks name or value");
        }
        parsed.value = parse_integer<std::int64_t>(value.value(), context + " item '" + parsed.name + "'");
        type.items.push_back(std::move(parsed));
      }
      if (type.items.empty()) {
        throw FmuError("model description: " + context + " has no <Item>");
      }
    }
    types.push_back(std::move(type));
  }
  return types;
}

/// The start value of @p node: the start attribute, or the <Start value=""/> children of
/// String and Binary variables joined by spaces.
std::optional<std::string> parse_start(const pugi::xml_node& node) {
  if (const pugi::xml_attribute start = node.attribute("start")) {
    return std::string(start.value());
  }
  std::optional<std::string> joined;
  for (const pugi::xml_node& start : node.children("Start")) {
    if (joined) {
      *joined += ' ';
    } else {
      joined.emplace();
    }
    *joined += start.attribute("value").value();
  }
  return joined;
}

ModelVariable parse_variable(const pugi::xml_node& node, std::size_t index, const std::vector<TypeDefinition>& types) {
  ModelVariable variable;
  variable.type = node.name();
  variable.name = node.attribute("name").value();
  if (!contains(VARIABLE_TYPES, variable.type)) {
    throw FmuError("model description: unknown element <" + variable.type + "> in <ModelVariables> (" +
                   variable_label(variable, index) + ")");
  }
  if (variable.name.empty()) {
    throw FmuError("model description: " + variable_label(variable, index) + " has no name");
  }
  const std::string label = variable_label(variable, index);

  const pugi::xml_attribute value_reference = node.attribute("valueReference");
  if (!value_reference) {
    throw FmuError("model description: " + label + " has no valueReference");
  }
  variable.value_reference = parse_integer<std::uint32_t>(value_reference.value(), label + " valueReference");

  variable.causality = node.attribute("causality").as_string("local");
  if (!contains(CAUSALITIES, variable.causality)) {
    throw FmuError("model description: " + label + " has unknown causality '" + variable.causality + "'");
  }
  variable.variability =
      node.attribute("variability").as_string(is_float_type(variable.type) ? "continuous" : "discrete");
  if (!contains(VARIABILITIES, variable.variability)) {
    throw FmuError("model description: " + label + " has unknown variability '" + variable.variability + "'");
  }
  if (variable.variability == "continuous" && !is_float_type(variable.type)) {
    throw FmuError("model description: " + label + " is <" + variable.type +
                   "> but variability is 'continuous' (only Float32/Float64 may be continuous)");
  }
  variable.initial = node.attribute("initial").value();
  if (!variable.initial.empty() && !contains(INITIALS, variable.initial)) {
    throw FmuError("model description: " + label + " has unknown initial '" + variable.initial + "'");
  }

  variable.declared_type = node.attribute("declaredType").value();
  const TypeDefinition* declared = nullptr;
  if (!variable.declared_type.empty()) {
    const auto found = std::find_if(types.begin(), types.end(),
                                    [&](const TypeDefinition& t) { return t.name == variable.declared_type; });
    if (found == types.end()) {
      throw FmuError("model description: " + label + " has declaredType '" + variable.declared_type +
                     "', which is not in <TypeDefinitions>");
    }
    declared = &*found;
  }
  if (variable.type == "Enumeration" && (declared == nullptr || declared->kind != "EnumerationType")) {
    throw FmuError("model description: " + label + " is an <Enumeration> without an EnumerationType declaredType");
  }
  variable.unit = node.attribute("unit").value();
  if (variable.unit.empty() && declared != nullptr) {
    variable.unit = declared->unit;
  }

  variable.start = parse_start(node);
  variable.min = optional_text(node, "min");
  variable.max = optional_text(node, "max");
  variable.description = node.attribute("description").value();

  for (const pugi::xml_node& dimension : node.children("Dimension")) {
    Dimension parsed;
    const pugi::xml_attribute start = dimension.attribute("start");
    const pugi::xml_attribute reference = dimension.attribute("valueReference");
    if (static_cast<bool>(start) == static_cast<bool>(reference)) {
      throw FmuError("model description: a <Dimension> of " + label +
                     " must have exactly one of start and valueReference");
    }
    if (start) {
      parsed.start = parse_integer<std::uint64_t>(start.value(), label + " <Dimension start>");
    } else {
      parsed.value_reference = parse_integer<std::uint32_t>(reference.value(), label + " <Dimension valueReference>");
    }
    variable.dimensions.push_back(parsed);
  }
  return variable;
}

/// Checks that every Dimension valueReference names a UInt64 structural parameter.
void check_dimensions(const ModelDescription& description) {
  for (const ModelVariable& variable : description.variables()) {
    for (const Dimension& dimension : variable.dimensions) {
      if (!dimension.value_reference) {
        continue;
      }
      const ModelVariable* size = description.find_variable(*dimension.value_reference);
      const std::string prefix = "model description: a <Dimension> of variable '" + variable.name +
                                 "' refers to valueReference " + std::to_string(*dimension.value_reference);
      if (size == nullptr) {
        throw FmuError(prefix + ", which is not a variable");
      }
      if (size->causality != "structuralParameter") {
        throw FmuError(prefix + " ('" + size->name + "'), which is not a structural parameter (causality '" +
                       size->causality + "')");
      }
      if (size->type != "UInt64") {
        throw FmuError(prefix + " ('" + size->name + "'), which is <" + size->type + ">, not <UInt64>");
      }
    }
  }
}

}  // namespace

const ModelVariable* ModelDescription::find_variable(std::string_view name) const {
  const auto found = m_index_by_name.find(std::string(name));
  return found == m_index_by_name.end() ? nullptr : &m_variables[found->second];
}

const ModelVariable* ModelDescription::find_variable(std::uint32_t value_reference) const {
  const auto found = m_index_by_value_reference.find(value_reference);
  return found == m_index_by_value_reference.end() ? nullptr : &m_variables[found->second];
}

const ModelVariable& ModelDescription::variable(std::string_view name) const {
  const ModelVariable* found = find_variable(name);
  if (found == nullptr) {
    throw FmuError("FMU '" + m_model_name + "' has no variable named '" + std::string(name) + "'");
  }
  return *found;
}

const ModelVariable& ModelDescription::variable(std::uint32_t value_reference) const {
  const ModelVariable* found = find_variable(value_reference);
  if (found == nullptr) {
    throw FmuError("FMU '" + m_model_name + "' has no variable with valueReference " + std::to_string(value_reference));
  }
  return *found;
}

const TypeDefinition* ModelDescription::find_type(std::string_view name) const {
  const auto found = std::find_if(m_type_definitions.begin(), m_type_definitions.end(),
                                  [&](const TypeDefinition& t) { return t.name == name; });
  return found == m_type_definitions.end() ? nullptr : &*found;
}

std::size_t ModelDescription::array_size(const ModelVariable& variable,
                                         const std::map<std::uint32_t, std::uint64_t>& structural_values) const {
  std::uint64_t size = 1;
  for (const Dimension& dimension : variable.dimensions) {
    std::uint64_t extent = 0;
    if (dimension.start) {
      extent = *dimension.start;
    } else {
      const std::uint32_t reference = *dimension.value_reference;
      if (const auto overridden = structural_values.find(reference); overridden != structural_values.end()) {
        extent = overridden->second;
      } else {
        const ModelVariable& parameter = this->variable(reference);
        if (!parameter.start) {
          throw FmuError("cannot size variable '" + variable.name + "': structural parameter '" + parameter.name +
                         "' has no start value and was not set");
        }
        extent = parse_integer<std::uint64_t>(*parameter.start, "start of '" + parameter.name + "'");
      }
    }
    if (extent != 0 && size > std::numeric_limits<std::size_t>::max() / extent) {
      throw FmuError("cannot size variable '" + variable.name + "': the element count overflows");
    }
    size *= extent;
  }
  return static_cast<std::size_t>(size);
}

ModelDescription parse_model_description(const std::string& xml_text) {
  pugi::xml_document document;
  const pugi::xml_parse_result parsed = document.load_buffer(xml_text.data(), xml_text.size());
  if (!parsed) {
    throw FmuError(std::string("model description is not well-formed XML: ") + parsed.description() + " at byte " +
                   std::to_string(parsed.offset));
  }
  const pugi::xml_node root = document.child("fmiModelDescription");
  if (!root) {
    throw FmuError("model description has no <fmiModelDescription> root element");
  }

  ModelDescription description;
  description.m_fmi_version = root.attribute("fmiVersion").value();
  if (description.m_fmi_version.rfind("3.", 0) != 0) {
    throw FmuError("model description has fmiVersion '" + description.m_fmi_version +
                   "'; this importer loads FMI 3.x FMUs only");
  }
  description.m_model_name = root.attribute("modelName").value();
  if (description.m_model_name.empty()) {
    throw FmuError("model description has no modelName");
  }
  description.m_instantiation_token = root.attribute("instantiationToken").value();
  if (description.m_instantiation_token.empty()) {
    throw FmuError("model description of '" + description.m_model_name + "' has no instantiationToken");
  }
  description.m_description = root.attribute("description").value();
  description.m_generation_tool = root.attribute("generationTool").value();

  const pugi::xml_node co_simulation = root.child("CoSimulation");
  if (!co_simulation) {
    throw FmuError("model description of '" + description.m_model_name +
                   "' has no <CoSimulation> element; this importer loads Co-Simulation FMUs only");
  }
  description.m_co_simulation = parse_co_simulation(co_simulation);

  if (const pugi::xml_node experiment = root.child("DefaultExperiment")) {
    const std::string context = "<DefaultExperiment>";
    DefaultExperiment parsed_experiment;
    parsed_experiment.start_time_s = optional_double(experiment, "startTime", context);
    parsed_experiment.stop_time_s = optional_double(experiment, "stopTime", context);
    parsed_experiment.tolerance = optional_double(experiment, "tolerance", context);
    parsed_experiment.step_size_s = optional_double(experiment, "stepSize", context);
    description.m_default_experiment = parsed_experiment;
  }

  for (const pugi::xml_node& category : root.child("LogCategories").children("Category")) {
    description.m_log_categories.push_back(
        {category.attribute("name").value(), category.attribute("description").value()});
  }
  for (const pugi::xml_node& unit : root.child("UnitDefinitions").children("Unit")) {
    description.m_unit_names.emplace_back(unit.attribute("name").value());
  }
  description.m_type_definitions = parse_type_definitions(root.child("TypeDefinitions"));

  const pugi::xml_node variables = root.child("ModelVariables");
  std::size_t index = 0;
  bool has_independent = false;
  for (const pugi::xml_node& node : variables.children()) {
    if (node.type() != pugi::node_element) {
      continue;
    }
    ModelVariable variable = parse_variable(node, index, description.m_type_definitions);
    if (!description.m_index_by_name.emplace(variable.name, index).second) {
      throw FmuError("model description: variable name '" + variable.name + "' is used twice");
    }
    if (const auto [other, inserted] = description.m_index_by_value_reference.emplace(variable.value_reference, index);
        !inserted) {
      throw FmuError("model description: variables '" + description.m_variables[other->second].name + "' and '" +
                     variable.name + "' have the same valueReference " + std::to_string(variable.value_reference));
    }
    if (variable.causality == "independent") {
      if (has_independent) {
        throw FmuError("model description: more than one independent variable ('" +
                       description.independent_variable().name + "' and '" + variable.name + "')");
      }
      if (!is_float_type(variable.type) || variable.is_array()) {
        throw FmuError("model description: the independent variable '" + variable.name +
                       "' must be a scalar Float32 or Float64");
      }
      has_independent = true;
      description.m_independent_index = index;
    }
    description.m_variables.push_back(std::move(variable));
    ++index;
  }
  if (!has_independent) {
    throw FmuError("model description of '" + description.m_model_name +
                   "' has no variable with causality 'independent'");
  }
  check_dimensions(description);
  return description;
}

ModelDescription load_model_description(const std::filesystem::path& path) {
  const std::string text = read_text_file(path);
  try {
    return parse_model_description(text);
  } catch (const FmuError& error) {
    throw FmuError("'" + path.string() + "': " + error.what());
  }
}

}  // namespace tissue::host
