// The FMI 2.0 writer (see model_description_xml.hpp).
#include "fmi2/model_description_xml.hpp"

#include "fmi3/model_description_xml.hpp"

#include <sstream>

namespace tissue::fmi2 {
namespace {

using fmi3::Causality;
using fmi3::Variability;
using fmi3::xml_attribute;
using fmi3::xml_escaped;

void write_type_definitions(std::ostream& out, const ModelDescription& description) {
  if (description.enumerations.empty()) return;
  out << "  <TypeDefinitions>\n";
  for (const fmi3::EnumerationType& type : description.enumerations) {
    out << "    <SimpleType";
    xml_attribute(out, "name", type.name);
    xml_attribute(out, "description", type.description);
    out << ">\n      <Enumeration>\n";
    fmi3::write_enumeration_items(out, type, "        ");
    out << "      </Enumeration>\n    </SimpleType>\n";
  }
  out << "  </TypeDefinitions>\n\n";
}

void write_scalar(std::ostream& out, const Scalar& scalar, std::size_t value_reference) {
  const VariableInfo& info = *scalar.variable;
  if (info.type != fmi3::VariableType::float64 && info.variability == Variability::continuous) {
    throw fmi3::SchemaError(std::string(info.name) + ": only a Real can be continuous in FMI 2.0");
  }
  out << "    <ScalarVariable";
  xml_attribute(out, "name", scalar.name);
  out << " valueReference=\"" << value_reference << '"';
  if (info.causality == Causality::structural_parameter) {
    throw fmi3::SchemaError(std::string(info.name) + ": a structural parameter has no FMI 2.0 causality");
  }
  xml_attribute(out, "causality", fmi3::to_string(info.causality));
  xml_attribute(out, "variability", fmi3::to_string(info.variability));
  out << "\n      description=\"" << xml_escaped(info.description) << "\">\n      <" << to_string(scalar.type);
  xml_attribute(out, "declaredType", info.declared_type);
  xml_attribute(out, "unit", info.unit);
  xml_attribute(out, "start", scalar.start);
  if (scalar.type == ScalarType::real || scalar.type == ScalarType::integer) {
    xml_attribute(out, "min", info.min);
    xml_attribute(out, "max", info.max);
  }
  out << "/>\n    </ScalarVariable>\n";
}

void write_model_structure(std::ostream& out, const ScalarLayout& layout) {
  out << "  <ModelStructure>\n";
  for (const char* element : {"Outputs", "InitialUnknowns"}) {
    out << "    <" << element << ">\n";
    for (std::size_t k = 0; k < layout.scalars().size(); ++k) {
      if (layout.scalars()[k].variable->causality == Causality::output) {
        out << "      <Unknown index=\"" << k + 1 << "\"/>\n";  // 1-based position in ModelVariables
      }
    }
    out << "    </" << element << ">\n";
  }
  out << "  </ModelStructure>\n";
}

}  // namespace

std::string model_description_xml(const ScalarLayout& layout) {
  const ModelDescription& description = layout.description();
  std::ostringstream out;
  out.precision(17);
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  out << "<!-- The " << description.model_identifier
      << " FMU's model description (FMI 2.0 Co-Simulation), written by the build from the port schema in\n"
         "     fmu_src/ through fmi2/scalar_layout.hpp: do not edit. Reference: docs/FMI2.md. -->\n";
  out << "<fmiModelDescription\n  fmiVersion=\"2.0\"\n  modelName=\"" << xml_escaped(description.model_identifier)
      << "\"\n  guid=\"" << xml_escaped(description.instantiation_token) << "\"\n  description=\""
      << xml_escaped(description.description)
      << "\"\n  generationTool=\"tissue\"\n  variableNamingConvention=\"structured\"\n"
         "  numberOfEventIndicators=\"0\">\n\n";
  out << "  <CoSimulation\n    modelIdentifier=\"" << xml_escaped(description.model_identifier)
      << "\"\n    canHandleVariableCommunicationStepSize=\"true\"\n    canGetAndSetFMUstate=\"true\"\n"
         "    canSerializeFMUstate=\"true\"\n    canNotUseMemoryManagementFunctions=\"true\"/>\n\n";
  fmi3::write_unit_definitions(out, description);
  write_type_definitions(out, description);
  fmi3::write_log_categories_and_default_experiment(out, description);
  out << "  <ModelVariables>\n";
  for (std::size_t k = 0; k < layout.scalars().size(); ++k) write_scalar(out, layout.scalars()[k], k);
  out << "  </ModelVariables>\n\n";
  write_model_structure(out, layout);
  out << "\n</fmiModelDescription>\n";
  return out.str();
}

}  // namespace tissue::fmi2
