// model_description_xml (see model_description_xml.hpp).
#include "fmi3/model_description_xml.hpp"

#include <algorithm>
#include <array>
#include <exception>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <vector>

namespace tissue::fmi3 {
namespace {

struct UnitDefinition {
  std::string_view name;
  int kg, m, s;  ///< exponents of the SI base units
};

// Every unit the project's FMUs may use; a new one is added here with its base units.
constexpr auto UNITS = std::to_array<UnitDefinition>({
    {"1", 0, 0, 0},     {"m", 0, 1, 0},      {"s", 0, 0, 1},      {"kg", 1, 0, 0},    {"N", 1, 1, -2},
    {"Pa", 1, -1, -2},  {"J", 1, 2, -2},     {"N/m", 1, 0, -2},   {"N/s", 1, 1, -3},  {"J/m2", 1, 0, -2},
    {"kg/m3", 1, -3, 0}, {"m/s", 0, 1, -1},  {"m/s2", 0, 1, -2},  {"1/s", 0, 0, -1},  {"Hz", 0, 0, -1},
    {"N.s/m", 1, 0, -1},
});

}  // namespace

std::string xml_escaped(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

int write_description_main(int argc, char** argv, const char* what, const std::function<std::string()>& make_xml) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " OUTPUT.xml\n";
    return 2;
  }
  try {
    const std::string xml = make_xml();
    std::ifstream existing(argv[1], std::ios::binary);
    if (existing && std::string(std::istreambuf_iterator<char>(existing), {}) == xml) return 0;
    existing.close();
    std::ofstream out(argv[1], std::ios::binary | std::ios::trunc);
    out << xml;
    if (!out) {
      std::cerr << argv[1] << ": cannot be written\n";
      return 1;
    }
  } catch (const std::exception& error) {
    std::cerr << what << ": " << error.what() << "\n";
    return 1;
  }
  return 0;
}

void write_unit_definitions(std::ostream& out, const ModelDescription& description) {
  std::vector<std::string_view> used;
  for (const VariableInfo& info : description.variables) {
    if (info.unit.empty()) continue;
    if (std::ranges::find(UNITS, info.unit, &UnitDefinition::name) == UNITS.end()) {
      throw SchemaError(std::string(info.name) + ": unit '" + std::string(info.unit) +
                        "' has no SI definition (add it to UNITS in fmi3/model_description_xml.cpp)");
    }
    if (std::ranges::find(used, info.unit) == used.end()) used.push_back(info.unit);
  }
  out << "  <UnitDefinitions>\n";
  for (const UnitDefinition& unit : UNITS) {  // in the table's order
    if (std::ranges::find(used, unit.name) == used.end()) continue;
    out << "    <Unit name=\"" << xml_escaped(unit.name) << "\"><BaseUnit";
    if (unit.kg != 0) out << " kg=\"" << unit.kg << '"';
    if (unit.m != 0) out << " m=\"" << unit.m << '"';
    if (unit.s != 0) out << " s=\"" << unit.s << '"';
    out << "/></Unit>\n";
  }
  out << "  </UnitDefinitions>\n\n";
}

void xml_attribute(std::ostream& out, std::string_view name, std::string_view value) {
  if (!value.empty()) out << ' ' << name << "=\"" << xml_escaped(value) << '"';
}

void write_enumeration_items(std::ostream& out, const EnumerationType& type, std::string_view indent) {
  for (const EnumerationItem& item : type.items) {
    out << indent << "<Item";
    xml_attribute(out, "name", item.name);
    out << " value=\"" << item.value << '"';
    xml_attribute(out, "description", item.description);
    out << "/>\n";
  }
}

void write_log_categories_and_default_experiment(std::ostream& out, const ModelDescription& description) {
  out << "  <LogCategories>\n";
  for (const LogCategory& category : description.log_categories) {
    out << "    <Category";
    xml_attribute(out, "name", category.name);
    xml_attribute(out, "description", category.description);
    out << "/>\n";
  }
  out << "  </LogCategories>\n\n";
  const DefaultExperiment& experiment = description.default_experiment;
  out << "  <DefaultExperiment startTime=\"" << experiment.start_time_s << "\" stopTime=\"" << experiment.stop_time_s
      << "\" stepSize=\"" << experiment.step_size_s << "\"/>\n\n";
}

namespace {


std::string element_name(VariableType type) { return std::string(to_string(type)); }

void write_enumerations(std::ostream& out, const ModelDescription& description) {
  if (description.enumerations.empty()) return;
  out << "  <TypeDefinitions>\n";
  for (const EnumerationType& type : description.enumerations) {
    out << "    <EnumerationType";
    xml_attribute(out, "name", type.name);
    xml_attribute(out, "description", type.description);
    out << ">\n";
    write_enumeration_items(out, type, "      ");
    out << "    </EnumerationType>\n";
  }
  out << "  </TypeDefinitions>\n\n";
}

void write_dimension(std::ostream& out, const Dimension& dimension) {
  if (dimension.size_vr >= 0) {
    out << "      <Dimension valueReference=\"" << dimension.size_vr << "\"/>\n";
  } else {
    out << "      <Dimension start=\"" << dimension.size << "\"/>\n";
  }
}

void write_variable(std::ostream& out, const VariableInfo& info) {
  const std::string element = element_name(info.type);
  out << "    <" << element;
  xml_attribute(out, "name", info.name);
  out << " valueReference=\"" << info.vr << '"';
  xml_attribute(out, "causality", to_string(info.causality));
  xml_attribute(out, "variability", to_string(info.variability));
  xml_attribute(out, "declaredType", info.declared_type);
  xml_attribute(out, "unit", info.unit);
  // A String's start is an element; every other type's an attribute.
  if (info.type != VariableType::string) xml_attribute(out, "start", info.start);
  xml_attribute(out, "min", info.min);
  xml_attribute(out, "max", info.max);
  out << "\n      description=\"" << xml_escaped(info.description) << '"';
  const bool has_children = info.rank > 0 || (info.type == VariableType::string && !info.start.empty());
  if (!has_children) {
    out << "/>\n";
    return;
  }
  out << ">\n";
  if (info.type == VariableType::string && !info.start.empty()) {
    out << "      <Start value=\"" << xml_escaped(info.start) << "\"/>\n";
  }
  for (int d = 0; d < info.rank; ++d) write_dimension(out, info.dimensions[static_cast<std::size_t>(d)]);
  out << "    </" << element << ">\n";
}

void write_model_structure(std::ostream& out, const ModelDescription& description) {
  out << "  <ModelStructure>\n";
  for (const char* element : {"Output", "InitialUnknown"}) {
    for (const VariableInfo& info : description.variables) {
      if (info.causality == Causality::output) out << "    <" << element << " valueReference=\"" << info.vr << "\"/>\n";
    }
  }
  out << "  </ModelStructure>\n";
}

}  // namespace

std::string model_description_xml(const ModelDescription& description) {
  if (!strictly_ordered(description.variables)) {
    throw SchemaError(std::string(description.model_identifier) +
                      ": the variables are not in strictly increasing value-reference order");
  }
  for (const VariableInfo& info : description.variables) {
    if (info.type == VariableType::binary && (info.causality != Causality::output || info.rank != 0)) {
      throw SchemaError(std::string(info.name) + ": a Binary variable must be a scalar output");
    }
  }
  std::ostringstream out;
  out.precision(17);
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out << "<!-- The " << description.model_identifier
      << " FMU's model description (FMI 3.0 Co-Simulation), written by the build from the port schema in\n"
         "     fmu_src/ (tissue-model-description): do not edit. Reference: docs/FMU_VARIABLES.md. -->\n";
  out << "<fmiModelDescription\n  fmiVersion=\"3.0\"\n  modelName=\"" << xml_escaped(description.model_identifier)
      << "\"\n  instantiationToken=\"" << xml_escaped(description.instantiation_token) << "\"\n  description=\""
      << xml_escaped(description.description)
      << "\"\n  generationTool=\"tissue\"\n  variableNamingConvention=\"structured\">\n\n";
  out << "  <CoSimulation\n    modelIdentifier=\"" << xml_escaped(description.model_identifier)
      << "\"\n    canHandleVariableCommunicationStepSize=\"true\"\n    canGetAndSetFMUState=\"true\"\n"
         "    canSerializeFMUState=\"true\"\n    providesIntermediateUpdate=\"false\"\n"
         "    canReturnEarlyAfterIntermediateUpdate=\"false\"\n    hasEventMode=\"false\"\n"
         "    providesEvaluateDiscreteStates=\"false\"/>\n\n";
  write_unit_definitions(out, description);
  write_enumerations(out, description);
  write_log_categories_and_default_experiment(out, description);
  out << "  <ModelVariables>\n";
  for (const VariableInfo& info : description.variables) write_variable(out, info);
  out << "  </ModelVariables>\n\n";
  write_model_structure(out, description);
  out << "\n</fmiModelDescription>\n";
  return out.str();
}

}  // namespace tissue::fmi3
