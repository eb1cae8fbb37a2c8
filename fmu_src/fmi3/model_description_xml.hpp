// The FMU's modelDescription.xml written from its port schema (the ModelDescription of
// variable_table.hpp): identity, Co-Simulation capabilities, units (with their SI base units),
// enumeration types, log categories, default experiment, variables and model structure. The build
// runs it for each FMU (tissue-model-description) and packages the result, so the XML importers read
// and the table the layer runs on are one source. Plain C++, no FMI headers.
#pragma once

#include "fmi3/variable_table.hpp"

#include <stdexcept>
#include <string>

namespace tissue::fmi3 {

/// A schema the writer cannot express: a unit whose SI base units it does not know, a variable
/// in the wrong order. The message names the variable.
class SchemaError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The modelDescription.xml of `description` (FMI 3.0, Co-Simulation). Throws SchemaError.
std::string model_description_xml(const ModelDescription& description);

}  // namespace tissue::fmi3
