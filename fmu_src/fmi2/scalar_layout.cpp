// ScalarLayout (see scalar_layout.hpp).
#include "fmi2/scalar_layout.hpp"

#include "fmi3/model_description_xml.hpp"

#include <sstream>

namespace tissue::fmi2 {

using fmi3::Causality;
using fmi3::VariableType;

namespace {

// The space-separated start of an array, one entry per element ("" when the variable has none; a
// single value for a whole array is repeated, as the 3.0 table allows).
std::vector<std::string> element_starts(const VariableInfo& info, std::size_t count) {
  std::vector<std::string> starts;
  std::istringstream in{std::string(info.start)};
  for (std::string word; in >> word;) starts.push_back(word);
  if (info.type == VariableType::string) starts = {std::string(info.start)};
  if (starts.empty()) return std::vector<std::string>(count);
  if (starts.size() == 1) return std::vector<std::string>(count, starts.front());
  if (starts.size() != count) {
    throw fmi3::SchemaError(std::string(info.name) + ": " + std::to_string(starts.size()) + " start values for " +
                            std::to_string(count) + " elements");
  }
  return starts;
}

}  // namespace

std::string_view to_string(ScalarType type) {
  switch (type) {
    case ScalarType::real:
      return "Real";
    case ScalarType::integer:
      return "Integer";
    case ScalarType::boolean:
      return "Boolean";
    case ScalarType::string:
      return "String";
    case ScalarType::enumeration:
      return "Enumeration";
  }
  return "Real";
}

bool ScalarLayout::carried(const VariableInfo& info) {
  if (info.type == VariableType::binary || info.causality == Causality::structural_parameter) return false;
  for (int d = 0; d < info.rank; ++d) {
    if (info.dimensions[static_cast<std::size_t>(d)].size_vr >= 0) return false;
  }
  return true;
}

std::size_t ScalarLayout::element_count(const VariableInfo& info) {
  std::size_t count = 1;
  for (int d = 0; d < info.rank; ++d) count *= info.dimensions[static_cast<std::size_t>(d)].size;
  return count;
}

ScalarType ScalarLayout::scalar_type(const VariableInfo& info) {
  switch (info.type) {
    case VariableType::float64:
      return ScalarType::real;
    case VariableType::boolean:
      return ScalarType::boolean;
    case VariableType::string:
      return ScalarType::string;
    case VariableType::enumeration:
      return ScalarType::enumeration;
    default:
      return ScalarType::integer;
  }
}

ScalarLayout::ScalarLayout(const ModelDescription& description) : m_description(description) {
  for (const VariableInfo& info : description.variables) {
    if (!carried(info)) continue;
    const std::size_t count = element_count(info);
    if (count > MAX_ELEMENTS) {
      throw fmi3::SchemaError(std::string(info.name) + ": " + std::to_string(count) +
                              " elements, more than the FMI 2.0 layer scalarizes (" + std::to_string(MAX_ELEMENTS) +
                              ")");
    }
    const std::vector<std::string> starts = element_starts(info, count);
    const std::size_t columns = info.rank == 2 ? info.dimensions[1].size : 1;
    for (std::size_t k = 0; k < count; ++k) {
      Scalar scalar;
      scalar.variable = &info;
      scalar.element = k;
      scalar.type = scalar_type(info);
      scalar.start = starts[k];
      scalar.name = std::string(info.name);
      if (info.rank == 1) scalar.name.append("[").append(std::to_string(k + 1)).append("]");
      if (info.rank == 2) {
        scalar.name.append("[").append(std::to_string(k / columns + 1)).append(",");
        scalar.name.append(std::to_string(k % columns + 1)).append("]");
      }
      m_scalars.push_back(std::move(scalar));
    }
  }
}

}  // namespace tissue::fmi2
