// The FMI 2.0 view of an FMU's port schema (fmi3/variable_table.hpp): FMI 2.0 has scalars only,
// so every array element is a variable of its own, named "x[i]" or "x[i,j]" (1-based, row-major,
// the standard's structured naming) with its own value reference: the scalars are numbered
// densely in the table's order, so a scalar's value reference is also its 0-based index in
// ModelVariables. The 2.0 types: Real (Float64), Integer (Int32, UInt32, UInt64, Int64),
// Boolean, String, Enumeration. Left out, since FMI 2.0 cannot carry them: Binary outputs,
// structural parameters, and the arrays they size (the Tissue's full surface).
#pragma once

#include "fmi3/variable_table.hpp"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace tissue::fmi2 {

using fmi3::ModelDescription;
using fmi3::VariableInfo;

enum class ScalarType { real, integer, boolean, string, enumeration };
/// The FMI 2.0 element name: "Real", "Integer", "Boolean", "String", "Enumeration".
std::string_view to_string(ScalarType type);

struct Scalar {
  const VariableInfo* variable = nullptr;
  std::size_t element = 0;  ///< row-major index in the variable's values
  std::string name;         ///< "gravity[3]", "contact.stiffness[1,2]", "time"
  ScalarType type = ScalarType::real;
  std::string start;  ///< this element's start ("" if none)
};

class ScalarLayout {
 public:
  /// The largest array scalarized (3x3 matrices are the largest in the schemas): the 2.0 calls
  /// gather a variable's elements in buffers of this size.
  static constexpr std::size_t MAX_ELEMENTS = 16;

  /// Throws fmi3::SchemaError for a carried array of more than MAX_ELEMENTS elements.
  explicit ScalarLayout(const ModelDescription& description);

  [[nodiscard]] const ModelDescription& description() const { return m_description; }
  [[nodiscard]] const std::vector<Scalar>& scalars() const { return m_scalars; }
  /// nullptr for a value reference past the last scalar.
  [[nodiscard]] const Scalar* find(std::uint32_t value_reference) const {
    return value_reference < m_scalars.size() ? &m_scalars[value_reference] : nullptr;
  }
  /// Elements of a fixed-size variable (1 for a scalar).
  [[nodiscard]] static std::size_t element_count(const VariableInfo& info);
  /// Whether the variable is in FMI 2.0 at all.
  [[nodiscard]] static bool carried(const VariableInfo& info);
  [[nodiscard]] static ScalarType scalar_type(const VariableInfo& info);

 private:
  const ModelDescription& m_description;
  std::vector<Scalar> m_scalars;
};

}  // namespace tissue::fmi2
