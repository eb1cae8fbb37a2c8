// The SSP of the pair (see system_structure.hpp).
#include "ssp/system_structure.hpp"

#include "fmi3/model_description_xml.hpp"
#include "ports/tissue_sample.hpp"

#include <algorithm>
#include <map>
#include <sstream>

namespace tissue::ssp {
namespace {

using fmi2::Scalar;
using fmi2::ScalarLayout;
using fmi2::ScalarType;
using fmi3::Causality;
using fmi3::SchemaError;

constexpr const char* TISSUE = "Tissue";
constexpr const char* HAPTIC = "HapticLoop";

// The scalar names of a variable of `rows` x `columns` ("x", "x[i]" or "x[i,j]").
std::vector<std::string> element_names(std::string_view name, std::uint64_t rows, std::uint64_t columns) {
  std::vector<std::string> names;
  if (rows * columns == 1) return {std::string(name)};
  for (std::uint64_t i = 1; i <= rows; ++i) {
    for (std::uint64_t j = 1; j <= columns; ++j) {
      std::string n(name);
      n.append("[").append(std::to_string(i));
      if (columns > 1) n.append(",").append(std::to_string(j));
      names.push_back(n.append("]"));
    }
  }
  return names;
}

const Scalar& scalar(const ScalarLayout& layout, const std::string& element, const std::string& name) {
  for (const Scalar& s : layout.scalars()) {
    if (s.name == name) return s;
  }
  throw SchemaError("SSP: " + element + " has no FMI 2.0 variable " + name);
}

void connector(std::ostream& out, const std::string& indent, const std::string& name, const char* kind,
               const Scalar& s) {
  out << indent << "<ssd:Connector name=\"" << fmi3::xml_escaped(name) << "\" kind=\"" << kind << "\">";
  if (s.type == ScalarType::enumeration) {
    out << "<ssc:Enumeration name=\"" << fmi3::xml_escaped(s.variable->declared_type) << "\"/>";
  } else {
    out << "<ssc:" << fmi2::to_string(s.type) << "/>";
  }
  out << "</ssd:Connector>\n";
}

}  // namespace

std::vector<Connection> connections(const ScalarLayout& tissue, const ScalarLayout& haptic) {
  std::vector<Connection> all;
  for (const ports::SampleField& field : ports::TISSUE_SAMPLE) {
    const auto from = element_names(field.tissue_output, field.rows, field.columns);
    const auto to = element_names(field.haptic_input, field.rows, field.columns);
    for (std::size_t k = 0; k < from.size(); ++k) all.push_back({TISSUE, from[k], HAPTIC, to[k]});
  }
  all.push_back({TISSUE, "sample.time", HAPTIC, std::string(ports::SAMPLE_TIME_INPUT)});
  for (const std::string& p : element_names("tool.position", 3, 1)) all.push_back({HAPTIC, p, TISSUE, p});
  all.push_back({HAPTIC, "tool.mode", TISSUE, "tool.mode"});
  for (const std::string& p : element_names("device.position", 3, 1)) all.push_back({"", p, HAPTIC, p});
  all.push_back({"", "device.toolMode", HAPTIC, "device.toolMode"});
  for (const std::string& f : element_names("device.force", 3, 1)) all.push_back({HAPTIC, f, "", f});

  // Each end an input of the right type, connected once; each start an output of the same type.
  std::map<std::string, int> ends;
  for (const Connection& c : all) {
    if (c.end_element.empty()) {  // a system output
      if (scalar(haptic, HAPTIC, c.start_connector).variable->causality != Causality::output) {
        throw SchemaError("SSP: HapticLoop." + c.start_connector + " is not an output");
      }
      continue;
    }
    const ScalarLayout& end_layout = c.end_element == TISSUE ? tissue : haptic;
    const Scalar& end = scalar(end_layout, c.end_element, c.end_connector);
    if (end.variable->causality != Causality::input) {
      throw SchemaError("SSP: " + c.end_element + "." + c.end_connector + " is not an input");
    }
    if (++ends[c.end_element + "." + c.end_connector] > 1) {
      throw SchemaError("SSP: " + c.end_element + "." + c.end_connector + " is connected twice");
    }
    if (c.start_element.empty()) continue;
    const Scalar& start = scalar(c.start_element == TISSUE ? tissue : haptic, c.start_element, c.start_connector);
    if (start.variable->causality != Causality::output || start.type != end.type) {
      throw SchemaError("SSP: " + c.start_element + "." + c.start_connector + " is not an output of " + c.end_element +
                        "." + c.end_connector + "'s type");
    }
  }
  return all;
}

std::string system_structure_ssd(const ScalarLayout& tissue, const ScalarLayout& haptic) {
  const std::vector<Connection> all = connections(tissue, haptic);
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<!-- Tissue and HapticLoop (FMI 2.0) wired as tissue-host wires them, written by the build from the\n"
         "     port lists in fmu_src/ (fmu_src/ssp/): do not edit. Reference: docs/FMI2.md. -->\n"
         "<ssd:SystemStructureDescription version=\"1.0\" name=\"TissueHaptic\"\n"
         "  xmlns:ssd=\"http://ssp-standard.org/SSP1/SystemStructureDescription\"\n"
         "  xmlns:ssc=\"http://ssp-standard.org/SSP1/SystemStructureCommon\">\n"
         "  <ssd:System name=\"TissueHaptic\" description=\"A hand's device pose through the haptic loop onto "
         "the tissue; the tissue's contact back to the haptic loop\">\n"
         "    <ssd:Connectors>\n";
  for (const Connection& c : all) {
    if (c.start_element.empty())
      connector(out, "      ", c.start_connector, "input", scalar(haptic, HAPTIC, c.end_connector));
    if (c.end_element.empty())
      connector(out, "      ", c.end_connector, "output", scalar(haptic, HAPTIC, c.start_connector));
  }
  out << "    </ssd:Connectors>\n    <ssd:ParameterBindings>\n"
         "      <ssd:ParameterBinding source=\"resources/TissueHaptic.ssv\"/>\n    </ssd:ParameterBindings>\n"
         "    <ssd:Elements>\n";
  for (const char* element : {TISSUE, HAPTIC}) {
    const ScalarLayout& layout = std::string(element) == TISSUE ? tissue : haptic;
    out << "      <ssd:Component name=\"" << element
        << "\" type=\"application/x-fmu-sharedlibrary\" source=\"resources/" << element
        << ".fmu\">\n        <ssd:Connectors>\n";
    for (const Connection& c : all) {
      if (c.start_element == element)
        connector(out, "          ", c.start_connector, "output", scalar(layout, element, c.start_connector));
      if (c.end_element == element)
        connector(out, "          ", c.end_connector, "input", scalar(layout, element, c.end_connector));
    }
    out << "        </ssd:Connectors>\n      </ssd:Component>\n";
  }
  out << "    </ssd:Elements>\n    <ssd:Connections>\n";
  for (const Connection& c : all) {
    out << "      <ssd:Connection ";
    if (!c.start_element.empty()) out << "startElement=\"" << c.start_element << "\" ";
    out << "startConnector=\"" << fmi3::xml_escaped(c.start_connector) << "\" ";
    if (!c.end_element.empty()) out << "endElement=\"" << c.end_element << "\" ";
    out << "endConnector=\"" << fmi3::xml_escaped(c.end_connector) << "\"/>\n";
  }
  out << "    </ssd:Connections>\n  </ssd:System>\n  <ssd:Enumerations>\n";
  for (const fmi3::EnumerationType& type : haptic.description().enumerations) {
    out << "    <ssc:Enumeration name=\"" << fmi3::xml_escaped(type.name) << "\">\n";
    for (const fmi3::EnumerationItem& item : type.items) {
      out << "      <ssc:Item name=\"" << fmi3::xml_escaped(item.name) << "\" value=\"" << item.value << "\"/>\n";
    }
    out << "    </ssc:Enumeration>\n";
  }
  out << "  </ssd:Enumerations>\n  <ssd:DefaultExperiment startTime=\"0\" stopTime=\"1\"/>\n"
         "</ssd:SystemStructureDescription>\n";
  return out.str();
}

std::string parameter_values_ssv() {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<ssv:ParameterSet version=\"1.0\" name=\"TissueHaptic\"\n"
         "  xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\">\n"
         "  <ssv:Parameters>\n"
         "    <ssv:Parameter name=\"Tissue.stepSize\"><ssv:Real value=\"0.001\"/></ssv:Parameter>\n"
         "    <ssv:Parameter name=\"HapticLoop.stepSize\"><ssv:Real value=\"0.001\"/></ssv:Parameter>\n"

         "  </ssv:Parameters>\n"
         "</ssv:ParameterSet>\n";
}

}  // namespace tissue::ssp
