// ModelDescription look-ups and the FMI spellings (see variable_table.hpp).
#include "fmi3/variable_table.hpp"

#include <algorithm>

namespace tissue::fmi3 {

const VariableInfo* ModelDescription::find(ValueReference vr) const {
  const auto it = std::ranges::lower_bound(variables, vr, {}, &VariableInfo::vr);
  return it != variables.end() && it->vr == vr ? &*it : nullptr;
}

const VariableInfo* ModelDescription::find(std::string_view name) const {
  const auto it = std::ranges::find(variables, name, &VariableInfo::name);
  return it != variables.end() ? &*it : nullptr;
}

const EnumerationType* ModelDescription::find_enumeration(std::string_view name) const {
  const auto it = std::ranges::find(enumerations, name, &EnumerationType::name);
  return it != enumerations.end() ? &*it : nullptr;
}

std::string_view to_string(VariableType type) {
  switch (type) {
    case VariableType::float64:
      return "Float64";
    case VariableType::int32:
      return "Int32";
    case VariableType::uint32:
      return "UInt32";
    case VariableType::int64:
      return "Int64";
    case VariableType::uint64:
      return "UInt64";
    case VariableType::boolean:
      return "Boolean";
    case VariableType::string:
      return "String";
    case VariableType::enumeration:
      return "Enumeration";
    case VariableType::binary:
      return "Binary";
  }
  return "";
}

std::string_view to_string(Causality causality) {
  switch (causality) {
    case Causality::independent:
      return "independent";
    case Causality::structural_parameter:
      return "structuralParameter";
    case Causality::parameter:
      return "parameter";
    case Causality::input:
      return "input";
    case Causality::output:
      return "output";
  }
  return "";
}

std::string_view to_string(Variability variability) {
  switch (variability) {
    case Variability::fixed:
      return "fixed";
    case Variability::tunable:
      return "tunable";
    case Variability::discrete:
      return "discrete";
    case Variability::continuous:
      return "continuous";
  }
  return "";
}

}  // namespace tissue::fmi3
