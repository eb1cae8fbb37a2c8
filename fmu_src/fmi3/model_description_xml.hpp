// The FMU's modelDescription.xml written from its port schema (the ModelDescription of
// variable_table.hpp): identity, Co-Simulation capabilities, units (with their SI base units),
// enumeration types, log categories, default experiment, variables and model structure. The build
// runs it for each FMU (tissue-model-description) and packages the result, so the XML importers read
// and the table the layer runs on are one source. Plain C++, no FMI headers.
#pragma once

#include "fmi3/variable_table.hpp"

#include <functional>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <string_view>

namespace tissue::fmi3 {

/// A schema the writer cannot express: a unit whose SI base units it does not know, a variable
/// in the wrong order. The message names the variable.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The modelDescription.xml of `description` (FMI 3.0, Co-Simulation). Throws SchemaError.
std::string model_description_xml(const ModelDescription& description);

// Shared with the FMI 2.0 writer (fmi2/model_description_xml.cpp), whose XML has the same units.
/// `text` with & < > " escaped for an attribute.
std::string xml_escaped(std::string_view text);
/// The body of the build's writers (write_model_description.cpp, FMI 3.0 and 2.0): `argv[1]` is the
/// output file, rewritten only when `make_xml()`'s text differs (so the FMU is not repackaged for
/// nothing). Returns main's exit code; errors to stderr, prefixed by `what`.
int write_description_main(int argc, char** argv, const char* what, const std::function<std::string()>& make_xml);
/// ` name="value"` (escaped), nothing when `value` is empty.
void xml_attribute(std::ostream& out, std::string_view name, std::string_view value);
/// The <Item .../> lines of an enumeration type, each indented by `indent` (the same element in FMI 2.0 and 3.0).
void write_enumeration_items(std::ostream& out, const EnumerationType& type, std::string_view indent);
/// <LogCategories> and <DefaultExperiment> (the same elements in FMI 2.0 and 3.0).
void write_log_categories_and_default_experiment(std::ostream& out, const ModelDescription& description);
/// <UnitDefinitions> of the units the variables use, in SI base units. Throws SchemaError for an unknown unit.
void write_unit_definitions(std::ostream& out, const ModelDescription& description);

}  // namespace tissue::fmi3
