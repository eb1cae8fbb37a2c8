// The values of a model's parameters, structural parameters and inputs, laid out from its variable
// table and started from the table's start values: the one place an FMU's settings live between
// fmi3Set* and the model reading them. Outputs are not stored; the model computes them.
// Stored variables have fixed sizes (an array sized by a structural parameter is an output).
#pragma once

#include "fmi3/variable_table.hpp"
#include "serial/byte_stream.hpp"

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace tissue::fmi3 {

/// A variable or value the instance refuses (unknown reference, wrong type or size, bad value):
/// fmi3Error with this message.
class VariableError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

class ValueStore {
 public:
  /// Lays out every stored variable and sets the start values. Throws std::logic_error for a table
  /// the store cannot hold (a malformed start, a stored array sized by a structural parameter).
  explicit ValueStore(const ModelDescription& model);

  [[nodiscard]] const ModelDescription& model() const { return *m_model; }

  /// Every stored value back to its start.
  void set_starts();
  /// The values of another store of the same model; allocates nothing for numbers and booleans.
  void copy_values_from(const ValueStore& other);

  // Typed reads by value reference, for the model (the variable must be stored and of that type).
  [[nodiscard]] double float64(ValueReference vr) const;
  [[nodiscard]] std::span<const double> float64_array(ValueReference vr) const;
  [[nodiscard]] std::int32_t int32(ValueReference vr) const;
  [[nodiscard]] std::int64_t int64(ValueReference vr) const;  ///< Int64 and enumerations
  [[nodiscard]] std::uint64_t uint64(ValueReference vr) const;
  [[nodiscard]] bool boolean(ValueReference vr) const;
  [[nodiscard]] const std::string& string(ValueReference vr) const;

  /// True if `info` is stored here (parameters, structural parameters, inputs).
  [[nodiscard]] bool holds(const VariableInfo& info) const;
  /// Element count of a stored variable.
  [[nodiscard]] std::size_t count(const VariableInfo& info) const;

  // FMI-typed reads and writes of one stored variable; `values.size()` must equal count(info).
  // T is double, std::int32_t, std::uint32_t, std::int64_t, std::uint64_t, bool or const char*.
  template <class T>
  void read(const VariableInfo& info, std::span<T> values) const;
  template <class T>
  void write(const VariableInfo& info, std::span<const T> values);

  /// True if any parameter or structural parameter differs from `other`'s (inputs ignored).
  [[nodiscard]] bool parameters_differ(const ValueStore& other) const;

  void serialize(serial::ByteWriter& writer) const;
  /// Reads what serialize() wrote for the same model; throws serial::FormatError (store unchanged).
  void deserialize(serial::ByteReader& reader);

 private:
  struct Slot {
    std::size_t offset = 0;
    std::size_t count = 0;
  };
  [[nodiscard]] const Slot& slot(const VariableInfo& info, VariableType type) const;
  /// Throws VariableError unless the stored values of `info` keep the schema's rules beyond their
  /// type and finiteness: enumeration items, min_norm.
  void check_rules(const VariableInfo& info) const;
  [[nodiscard]] const Slot& slot(ValueReference vr, VariableType type) const;

  const ModelDescription* m_model;
  std::vector<Slot> m_slots;  // per table row; count 0 for variables not stored
  std::vector<double> m_float64;
  std::vector<std::int64_t> m_integer;  // Int32, UInt32, Int64, enumerations and booleans
  std::vector<std::uint64_t> m_uint64;
  std::vector<std::string> m_string;
};

}  // namespace tissue::fmi3
