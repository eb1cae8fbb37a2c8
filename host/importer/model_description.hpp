// model_description.hpp - what the importer reads from an FMI 3.0 modelDescription.xml.
//
// Only what a co-simulation importer needs: the header attributes, the CoSimulation
// capabilities, the default experiment, log categories, units, type definitions and every
// model variable with its dimensions. parse_model_description() checks the rules an importer
// relies on (unique names and value references, known causality and variability, dimensions
// that refer to structural parameters, one independent variable) and refuses the rest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace tissue::host {

/// Attributes of the <CoSimulation> element (FMI 3.0 section 4.3.1); booleans default to false.
struct CoSimulationCapabilities {
  std::string model_identifier;
  bool needs_execution_tool = false;
  bool can_be_instantiated_only_once_per_process = false;
  bool can_get_and_set_fmu_state = false;
  bool can_serialize_fmu_state = false;
  bool provides_directional_derivatives = false;
  bool provides_adjoint_derivatives = false;
  bool provides_per_element_dependencies = false;
  bool can_handle_variable_communication_step_size = false;
  bool provides_intermediate_update = false;
  bool might_return_early_from_do_step = false;
  bool can_return_early_after_intermediate_update = false;
  bool has_event_mode = false;
  bool provides_evaluate_discrete_states = false;
  std::uint32_t max_output_derivative_order = 0;
  std::optional<double> fixed_internal_step_size_s;
  std::int32_t recommended_intermediate_input_smoothness = 0;
};

/// <DefaultExperiment>; each attribute is optional in the standard.
struct DefaultExperiment {
  std::optional<double> start_time_s;
  std::optional<double> stop_time_s;
  std::optional<double> tolerance;
  std::optional<double> step_size_s;
};

/// One <Category> of <LogCategories>.
struct LogCategory {
  std::string name;
  std::string description;
};

/// One <Item> of an <EnumerationType>.
struct EnumerationItem {
  std::string name;
  std::int64_t value = 0;
  std::string description;
};

/// One entry of <TypeDefinitions>, e.g. kind "EnumerationType" or "Float64Type".
struct TypeDefinition {
  std::string kind;
  std::string name;
  std::string description;
  std::string unit;                    ///< unit attribute of Float32Type/Float64Type, else empty
  std::vector<EnumerationItem> items;  ///< the items of an EnumerationType, else empty
};

/// One <Dimension> of an array variable: either a fixed size or a structural parameter's size.
struct Dimension {
  std::optional<std::uint64_t> start;            ///< fixed extent
  std::optional<std::uint32_t> value_reference;  ///< structural parameter giving the extent
};

/// One variable of <ModelVariables>.
struct ModelVariable {
  std::string type;  ///< element name: "Float64", "Int32", "Boolean", "Enumeration", ...
  std::string name;
  std::uint32_t value_reference = 0;
  std::string causality;      ///< "local" when absent
  std::string variability;    ///< "continuous" for Float32/Float64, "discrete" otherwise, when absent
  std::string initial;        ///< empty when absent
  std::string declared_type;  ///< empty when absent
  std::string unit;           ///< the unit attribute, or the declared type's unit, or empty
  /// start value as written; elements of an array separated by single spaces. For String and
  /// Binary it comes from the <Start value="..."/> children.
  std::optional<std::string> start;
  std::optional<std::string> min;
  std::optional<std::string> max;
  std::string description;
  std::vector<Dimension> dimensions;  ///< empty for a scalar

  [[nodiscard]] bool is_array() const { return !dimensions.empty(); }
};

/**
 * A parsed and checked model description. Built only by parse_model_description(); read-only
 * afterwards, so the name and value-reference indexes stay valid.
 */
class ModelDescription {
 public:
  [[nodiscard]] const std::string& fmi_version() const { return m_fmi_version; }
  [[nodiscard]] const std::string& model_name() const { return m_model_name; }
  [[nodiscard]] const std::string& instantiation_token() const { return m_instantiation_token; }
  [[nodiscard]] const std::string& description() const { return m_description; }
  [[nodiscard]] const std::string& generation_tool() const { return m_generation_tool; }
  [[nodiscard]] const CoSimulationCapabilities& co_simulation() const { return m_co_simulation; }
  [[nodiscard]] const std::optional<DefaultExperiment>& default_experiment() const { return m_default_experiment; }
  [[nodiscard]] const std::vector<LogCategory>& log_categories() const { return m_log_categories; }
  [[nodiscard]] const std::vector<std::string>& unit_names() const { return m_unit_names; }
  [[nodiscard]] const std::vector<TypeDefinition>& type_definitions() const { return m_type_definitions; }
  /// All variables in document order.
  [[nodiscard]] const std::vector<ModelVariable>& variables() const { return m_variables; }

  /// The variable called @p name, or nullptr.
  [[nodiscard]] const ModelVariable* find_variable(std::string_view name) const;
  /// The variable with value reference @p value_reference, or nullptr.
  [[nodiscard]] const ModelVariable* find_variable(std::uint32_t value_reference) const;
  /// The variable called @p name; throws FmuError naming it if there is none.
  [[nodiscard]] const ModelVariable& variable(std::string_view name) const;
  /// The variable with value reference @p value_reference; throws FmuError if there is none.
  [[nodiscard]] const ModelVariable& variable(std::uint32_t value_reference) const;
  /// The type definition called @p name, or nullptr.
  [[nodiscard]] const TypeDefinition* find_type(std::string_view name) const;
  /// The variable with causality "independent" (there is exactly one).
  [[nodiscard]] const ModelVariable& independent_variable() const { return m_variables[m_independent_index]; }

  /**
   * Number of scalar elements of @p variable: 1 for a scalar, else the product of its
   * dimensions. A dimension given by a structural parameter uses @p structural_values
   * [value reference] when present, else that parameter's start value. Throws FmuError if
   * a structural parameter has neither.
   */
  [[nodiscard]] std::size_t array_size(const ModelVariable& variable,
                                       const std::map<std::uint32_t, std::uint64_t>& structural_values = {}) const;

 private:
  friend ModelDescription parse_model_description(const std::string& xml_text);

  std::string m_fmi_version;
  std::string m_model_name;
  std::string m_instantiation_token;
  std::string m_description;
  std::string m_generation_tool;
  CoSimulationCapabilities m_co_simulation;
  std::optional<DefaultExperiment> m_default_experiment;
  std::vector<LogCategory> m_log_categories;
  std::vector<std::string> m_unit_names;
  std::vector<TypeDefinition> m_type_definitions;
  std::vector<ModelVariable> m_variables;
  std::unordered_map<std::string, std::size_t> m_index_by_name;
  std::unordered_map<std::uint32_t, std::size_t> m_index_by_value_reference;
  std::size_t m_independent_index = 0;
};

/**
 * Parses and checks an FMI 3.x modelDescription.xml document with a <CoSimulation> element.
 * Throws FmuError, naming the offending element, variable or attribute, if the XML is
 * malformed, fmiVersion does not start with "3.", modelName, instantiationToken or
 * CoSimulation/modelIdentifier is missing, a variable lacks a name or valueReference or
 * repeats one, a causality or variability is unknown (or continuous for a non-float type), a
 * declaredType is undefined, a Dimension refers to a missing variable or to one that is not a
 * UInt64 structural parameter, or there is not exactly one independent variable.
 */
[[nodiscard]] ModelDescription parse_model_description(const std::string& xml_text);

/// Reads and parses the model description file at @p path (errors name the file).
[[nodiscard]] ModelDescription load_model_description(const std::filesystem::path& path);

}  // namespace tissue::host
