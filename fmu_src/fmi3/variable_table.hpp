// The FMI 3.0 layer's description of a model: its identity and its variable table (name, type,
// causality, variability, unit, start, range, dimensions, description), enumeration types, log
// categories and default experiment. This is each FMU's port schema, written once
// (fmu_src/<fmu>/variables.cpp): the layer drives everything from it (which calls may set a
// variable, the start values, array sizes and typed get/set), and the build writes the FMU's
// modelDescription.xml from it (model_description_xml.hpp). Plain C++, no FMI headers.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <type_traits>

namespace tissue::fmi3 {

using ValueReference = std::uint32_t;

/// The element type in the XML. An enumeration is got and set as Int64 in FMI 3.
/// A Binary is an output only, scalar, got as bytes the model owns (Model::get_binary).
enum class VariableType { float64, int32, uint32, int64, uint64, boolean, string, enumeration, binary };
enum class Causality { independent, structural_parameter, parameter, input, output };
enum class Variability { fixed, tunable, discrete, continuous };

/// One array dimension: a fixed size, or the value reference of a structural parameter (size_vr >= 0).
struct Dimension {
  std::uint64_t size = 0;
  std::int64_t size_vr = -1;
};

struct VariableInfo {
  ValueReference vr;
  std::string_view name;
  VariableType type;
  Causality causality;
  Variability variability;
  std::string_view unit;           ///< "" for none
  std::string_view declared_type;  ///< enumeration type name, else ""
  /// As written in the XML ("" for outputs and the independent variable); arrays space separated;
  /// booleans "true"/"false".
  std::string_view start;
  std::string_view min, max;  ///< as in the XML, "" when absent
  std::array<Dimension, 2> dimensions;
  int rank = 0;  ///< 0 = scalar
  std::string_view description;
  /// A Float64 array whose Euclidean norm a set must keep above this (0: no such rule): a quaternion
  /// the model normalizes where it uses it. The layer refuses the set (ValueStore::write).
  double min_norm = 0.0;

  /// Parameters, structural parameters and inputs hold a value the importer sets (ValueStore).
  [[nodiscard]] constexpr bool is_stored() const {
    return causality == Causality::parameter || causality == Causality::structural_parameter ||
           causality == Causality::input;
  }
};

struct EnumerationItem {
  std::string_view name;
  std::int64_t value;
  std::string_view description;
};

struct EnumerationType {
  std::string_view name;
  std::string_view description;
  std::span<const EnumerationItem> items;
};

struct LogCategory {
  std::string_view name;
  std::string_view description;
};

/// The log categories the layer logs to (instance.cpp), with the model's words for what its warnings
/// and its events carry; the rest are the layer's own.
constexpr std::array<LogCategory, 5> layer_log_categories(std::string_view warnings, std::string_view events) {
  return {{{"logStatusWarning", warnings},
           {"logStatusError", "Calls that returned fmi3Error or fmi3Discard, with the reason"},
           {"logStatusFatal", "Calls that returned fmi3Fatal"},
           {"logCalls", "Every FMI function call with its arguments"},
           {"logEvents", events}}};
}

struct DefaultExperiment {
  double start_time_s = 0.0;
  double stop_time_s = 1.0;
  double step_size_s = 0.01;
};

/// Everything the layer knows of one FMU model.
struct ModelDescription {
  std::string_view model_identifier;
  std::string_view instantiation_token;
  std::span<const VariableInfo> variables;  ///< in strictly increasing value-reference order
  std::span<const EnumerationType> enumerations;
  std::string_view description;               ///< the model's description attribute
  std::span<const LogCategory> log_categories;  ///< the categories the layer logs to, with what each carries
  DefaultExperiment default_experiment;

  /// nullptr if no variable has this value reference / name.
  [[nodiscard]] const VariableInfo* find(ValueReference vr) const;
  [[nodiscard]] const VariableInfo* find(std::string_view name) const;
  [[nodiscard]] const EnumerationType* find_enumeration(std::string_view name) const;
};

/// Builds one VariableInfo by named steps: VariableInfo is an aggregate of many string_views, and
/// positional or partial designated initializers are easy to misorder (and GCC warns on the latter).
class Entry {
 public:
  constexpr Entry(ValueReference vr, std::string_view name, VariableType type, Causality causality,
                  Variability variability)
      : m_info{vr, name, type, causality, variability, {}, {}, {}, {}, {}, {}, 0, {}, 0.0} {}

  constexpr Entry& unit(std::string_view unit) {
    m_info.unit = unit;
    return *this;
  }
  constexpr Entry& declared_type(std::string_view declared_type) {
    m_info.declared_type = declared_type;
    return *this;
  }
  constexpr Entry& start(std::string_view start) {
    m_info.start = start;
    return *this;
  }
  constexpr Entry& min(std::string_view min) {
    m_info.min = min;
    return *this;
  }
  constexpr Entry& max(std::string_view max) {
    m_info.max = max;
    return *this;
  }
  constexpr Entry& shape(Dimension rows) {
    m_info.dimensions = {rows, Dimension{}};
    m_info.rank = 1;
    return *this;
  }
  constexpr Entry& shape(Dimension rows, Dimension columns) {
    m_info.dimensions = {rows, columns};
    m_info.rank = 2;
    return *this;
  }
  constexpr Entry& min_norm(double norm) {
    m_info.min_norm = norm;
    return *this;
  }
  constexpr Entry& describe(std::string_view description) {
    m_info.description = description;
    return *this;
  }
  // Implicit so that a table can list entries directly.
  constexpr operator VariableInfo() const { return m_info; }  // NOLINT(google-explicit-constructor)

 private:
  VariableInfo m_info;
};

template <class Vr>
constexpr Entry parameter(Vr vr, std::string_view name, VariableType type) {
  return {static_cast<ValueReference>(vr), name, type, Causality::parameter, Variability::fixed};
}
template <class Vr>
constexpr Entry tunable_parameter(Vr vr, std::string_view name, VariableType type) {
  return {static_cast<ValueReference>(vr), name, type, Causality::parameter, Variability::tunable};
}
template <class Vr>
constexpr Entry structural_parameter(Vr vr, std::string_view name, VariableType type) {
  return {static_cast<ValueReference>(vr), name, type, Causality::structural_parameter, Variability::fixed};
}
template <class Vr>
constexpr Entry input(Vr vr, std::string_view name, VariableType type, Variability variability) {
  return {static_cast<ValueReference>(vr), name, type, Causality::input, variability};
}
template <class Vr>
constexpr Entry output(Vr vr, std::string_view name, VariableType type, Variability variability) {
  return {static_cast<ValueReference>(vr), name, type, Causality::output, variability};
}
template <class Vr>
constexpr Entry independent_time(Vr vr) {
  return Entry(static_cast<ValueReference>(vr), "time", VariableType::float64, Causality::independent,
               Variability::continuous)
      .unit("s")
      .describe("Simulation time");
}

constexpr Dimension fixed_size(std::uint64_t size) { return {size, -1}; }
template <class Vr>
constexpr Dimension sized_by(Vr structural_parameter) {
  return {0, static_cast<std::int64_t>(structural_parameter)};
}

/// True if the C++ value type T gets and sets variables of `type` (an enumeration is Int64 in FMI 3);
/// T is double, std::int32_t, std::uint32_t, std::int64_t, std::uint64_t, bool or const char*.
template <class T>
constexpr bool accepts(VariableType type) {
  if constexpr (std::is_same_v<T, double>) return type == VariableType::float64;
  if constexpr (std::is_same_v<T, std::int32_t>) return type == VariableType::int32;
  if constexpr (std::is_same_v<T, std::uint32_t>) return type == VariableType::uint32;
  if constexpr (std::is_same_v<T, std::int64_t>)
    return type == VariableType::int64 || type == VariableType::enumeration;
  if constexpr (std::is_same_v<T, std::uint64_t>) return type == VariableType::uint64;
  if constexpr (std::is_same_v<T, bool>) return type == VariableType::boolean;
  if constexpr (std::is_same_v<T, const char*>) return type == VariableType::string;
  return false;
}

/// The FMI name of the accessor of T ("Float64", ..., "String").
template <class T>
constexpr std::string_view accessor_name() {
  if constexpr (std::is_same_v<T, double>) return "Float64";
  if constexpr (std::is_same_v<T, std::int32_t>) return "Int32";
  if constexpr (std::is_same_v<T, std::uint32_t>) return "UInt32";
  if constexpr (std::is_same_v<T, std::int64_t>) return "Int64";
  if constexpr (std::is_same_v<T, std::uint64_t>) return "UInt64";
  if constexpr (std::is_same_v<T, bool>) return "Boolean";
  return "String";
}

/// True if the table is in strictly increasing value-reference order (find() binary-searches).
constexpr bool strictly_ordered(std::span<const VariableInfo> variables) {
  for (std::size_t k = 1; k < variables.size(); ++k) {
    if (variables[k - 1].vr >= variables[k].vr) return false;
  }
  return true;
}

/// `a` and `b` as one table in value-reference order (a schema written in parts, such as an FMU's own
/// variables and the tissue sample's, ports/tissue_sample.hpp).
template <std::size_t N, std::size_t M>
constexpr std::array<VariableInfo, N + M> merged(const std::array<VariableInfo, N>& a,
                                                 const std::array<VariableInfo, M>& b) {
  std::array<VariableInfo, N + M> all{};
  std::copy(a.begin(), a.end(), all.begin());
  std::copy(b.begin(), b.end(), all.begin() + static_cast<std::ptrdiff_t>(N));
  std::sort(all.begin(), all.end(), [](const VariableInfo& l, const VariableInfo& r) { return l.vr < r.vr; });
  return all;
}

/// The FMI spelling: "Float64", "structuralParameter", "continuous", ...
std::string_view to_string(VariableType type);
std::string_view to_string(Causality causality);
std::string_view to_string(Variability variability);

}  // namespace tissue::fmi3
