// ValueStore (see value_store.hpp).
#include "fmi3/value_store.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>
#include <type_traits>

namespace tissue::fmi3 {
namespace {

enum class Storage { float64, integer, uint64, string };

Storage storage_of(VariableType type) {
  switch (type) {
    case VariableType::float64:
      return Storage::float64;
    case VariableType::uint64:
      return Storage::uint64;
    case VariableType::string:
      return Storage::string;
    case VariableType::int32:
    case VariableType::uint32:
    case VariableType::int64:
    case VariableType::enumeration:
    case VariableType::boolean:
    case VariableType::binary:  // never stored (an output): value_store never gets here for one
      return Storage::integer;
  }
  return Storage::integer;
}

std::vector<std::string> split(std::string_view text) {
  std::vector<std::string> words;
  std::istringstream stream{std::string(text)};
  for (std::string word; stream >> word;) words.push_back(word);
  return words;
}

template <class T>
T parse_number(const std::string& word, const VariableInfo& info) {
  T value{};
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size()) {
    throw std::logic_error("variable table: start '" + word + "' of " + std::string(info.name) + " is not a " +
                           std::string(to_string(info.type)));
  }
  return value;
}

}  // namespace

ValueStore::ValueStore(const ModelDescription& model) : m_model(&model) {
  m_slots.resize(model.variables.size());
  for (std::size_t k = 0; k < model.variables.size(); ++k) {
    const VariableInfo& info = model.variables[k];
    if (!info.is_stored()) continue;
    std::size_t n = 1;
    for (int d = 0; d < info.rank; ++d) {
      const Dimension& dimension = info.dimensions[static_cast<std::size_t>(d)];
      if (dimension.size_vr >= 0) {
        throw std::logic_error("variable table: " + std::string(info.name) +
                               " is stored but sized by a structural parameter");
      }
      n *= dimension.size;
    }
    Slot& s = m_slots[k];
    s.count = n;
    switch (storage_of(info.type)) {
      case Storage::float64:
        s.offset = m_float64.size();
        m_float64.resize(m_float64.size() + n);
        break;
      case Storage::integer:
        s.offset = m_integer.size();
        m_integer.resize(m_integer.size() + n);
        break;
      case Storage::uint64:
        s.offset = m_uint64.size();
        m_uint64.resize(m_uint64.size() + n);
        break;
      case Storage::string:
        s.offset = m_string.size();
        m_string.resize(m_string.size() + n);
        break;
    }
  }
  set_starts();
}

void ValueStore::set_starts() {
  for (std::size_t k = 0; k < m_model->variables.size(); ++k) {
    const VariableInfo& info = m_model->variables[k];
    const Slot& s = m_slots[k];
    if (s.count == 0) continue;
    if (info.type == VariableType::string) {
      m_string[s.offset] = std::string(info.start);
      continue;
    }
    const std::vector<std::string> words = split(info.start);
    if (words.size() != s.count) {
      throw std::logic_error("variable table: " + std::string(info.name) + " has " + std::to_string(words.size()) +
                             " start values for " + std::to_string(s.count) + " elements");
    }
    for (std::size_t e = 0; e < s.count; ++e) {
      const std::string& word = words[e];
      switch (info.type) {
        case VariableType::float64:
          m_float64[s.offset + e] = parse_number<double>(word, info);
          break;
        case VariableType::uint64:
          m_uint64[s.offset + e] = parse_number<std::uint64_t>(word, info);
          break;
        case VariableType::boolean:
          if (word != "true" && word != "false") {
            throw std::logic_error("variable table: Boolean start of " + std::string(info.name) + " is '" + word + "'");
          }
          m_integer[s.offset + e] = word == "true" ? 1 : 0;
          break;
        default:
          m_integer[s.offset + e] = parse_number<std::int64_t>(word, info);
          break;
      }
    }
  }
}

void ValueStore::copy_values_from(const ValueStore& other) {
  std::copy(other.m_float64.begin(), other.m_float64.end(), m_float64.begin());
  std::copy(other.m_integer.begin(), other.m_integer.end(), m_integer.begin());
  std::copy(other.m_uint64.begin(), other.m_uint64.end(), m_uint64.begin());
  for (std::size_t k = 0; k < m_string.size(); ++k) {
    if (m_string[k] != other.m_string[k]) m_string[k] = other.m_string[k];
  }
}

bool ValueStore::holds(const VariableInfo& info) const {
  const auto index = static_cast<std::size_t>(&info - m_model->variables.data());
  return index < m_slots.size() && m_slots[index].count > 0;
}

std::size_t ValueStore::count(const VariableInfo& info) const { return slot(info, info.type).count; }

const ValueStore::Slot& ValueStore::slot(const VariableInfo& info, VariableType type) const {
  const auto index = static_cast<std::size_t>(&info - m_model->variables.data());
  if (index >= m_slots.size() || m_slots[index].count == 0) {
    throw std::logic_error(std::string(info.name) + " holds no stored value");
  }
  if (storage_of(info.type) != storage_of(type)) {
    throw std::logic_error(std::string(info.name) + " is not stored as " + std::string(to_string(type)));
  }
  return m_slots[index];
}

const ValueStore::Slot& ValueStore::slot(ValueReference vr, VariableType type) const {
  const VariableInfo* info = m_model->find(vr);
  if (info == nullptr) throw std::logic_error("no variable has value reference " + std::to_string(vr));
  return slot(*info, type);
}

double ValueStore::float64(ValueReference vr) const { return m_float64[slot(vr, VariableType::float64).offset]; }

std::span<const double> ValueStore::float64_array(ValueReference vr) const {
  const Slot& s = slot(vr, VariableType::float64);
  return std::span<const double>(m_float64).subspan(s.offset, s.count);
}

std::int32_t ValueStore::int32(ValueReference vr) const {
  return static_cast<std::int32_t>(m_integer[slot(vr, VariableType::int32).offset]);
}

std::int64_t ValueStore::int64(ValueReference vr) const { return m_integer[slot(vr, VariableType::int64).offset]; }

std::uint64_t ValueStore::uint64(ValueReference vr) const { return m_uint64[slot(vr, VariableType::uint64).offset]; }

bool ValueStore::boolean(ValueReference vr) const { return m_integer[slot(vr, VariableType::boolean).offset] != 0; }

const std::string& ValueStore::string(ValueReference vr) const {
  return m_string[slot(vr, VariableType::string).offset];
}

template <class T>
void ValueStore::read(const VariableInfo& info, std::span<T> values) const {
  if (!accepts<T>(info.type)) throw std::logic_error("ValueStore::read: wrong type for " + std::string(info.name));
  const Slot& s = slot(info, info.type);
  if (values.size() != s.count) {
    throw VariableError(std::string(info.name) + " has " + std::to_string(s.count) + " values, " +
                        std::to_string(values.size()) + " were asked for");
  }
  for (std::size_t e = 0; e < s.count; ++e) {
    if constexpr (std::is_same_v<T, double>) {
      values[e] = m_float64[s.offset + e];
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      values[e] = m_uint64[s.offset + e];
    } else if constexpr (std::is_same_v<T, const char*>) {
      values[e] = m_string[s.offset + e].c_str();
    } else if constexpr (std::is_same_v<T, bool>) {
      values[e] = m_integer[s.offset + e] != 0;
    } else {
      values[e] = static_cast<T>(m_integer[s.offset + e]);
    }
  }
}

template <class T>
void ValueStore::write(const VariableInfo& info, std::span<const T> values) {
  if (!accepts<T>(info.type)) throw std::logic_error("ValueStore::write: wrong type for " + std::string(info.name));
  const Slot& s = slot(info, info.type);
  if (values.size() != s.count) {
    throw VariableError(std::string(info.name) + " takes " + std::to_string(s.count) + " values, got " +
                        std::to_string(values.size()));
  }
  for (std::size_t e = 0; e < s.count; ++e) {
    if constexpr (std::is_same_v<T, double>) {
      // No setting of any model is meaningful as NaN or infinity: refused here, for every variable.
      if (!std::isfinite(values[e])) {
        throw VariableError(std::string(info.name) + " must be finite, got " + std::to_string(values[e]));
      }
      m_float64[s.offset + e] = values[e];
    } else if constexpr (std::is_same_v<T, std::uint64_t>) {
      m_uint64[s.offset + e] = values[e];
    } else if constexpr (std::is_same_v<T, const char*>) {
      if (values[e] == nullptr) throw VariableError(std::string(info.name) + ": a null string");
      m_string[s.offset + e] = values[e];
    } else if constexpr (std::is_same_v<T, bool>) {
      m_integer[s.offset + e] = values[e] ? 1 : 0;
    } else {
      m_integer[s.offset + e] = static_cast<std::int64_t>(values[e]);
    }
  }
  check_rules(info);
}

void ValueStore::check_rules(const VariableInfo& info) const {
  const Slot& s = slot(info, info.type);
  if (info.min_norm > 0.0) {
    double squared = 0.0;
    for (std::size_t e = 0; e < s.count; ++e) squared += m_float64[s.offset + e] * m_float64[s.offset + e];
    if (!(std::sqrt(squared) > info.min_norm)) {
      throw VariableError(std::string(info.name) + " must have a norm above " + std::to_string(info.min_norm) +
                          " (a quaternion the model normalizes), got " + std::to_string(std::sqrt(squared)));
    }
  }
  if (info.type == VariableType::enumeration) {
    const EnumerationType* type = m_model->find_enumeration(info.declared_type);
    for (std::size_t e = 0; type != nullptr && e < s.count; ++e) {
      const std::int64_t v = m_integer[s.offset + e];
      if (std::ranges::none_of(type->items, [v](const EnumerationItem& item) { return item.value == v; })) {
        std::string items;
        for (const EnumerationItem& item : type->items) {
          items += (items.empty() ? "" : ", ") + std::to_string(item.value) + " (" + std::string(item.name) + ")";
        }
        throw VariableError(std::string(info.name) + " must be one of " + items + ", got " + std::to_string(v));
      }
    }
  }
}

#define TISSUE_VALUE_STORE_TYPES(T)                                           \
  template void ValueStore::read<T>(const VariableInfo&, std::span<T>) const; \
  template void ValueStore::write<T>(const VariableInfo&, std::span<const T>);
TISSUE_VALUE_STORE_TYPES(double)
TISSUE_VALUE_STORE_TYPES(std::int32_t)
TISSUE_VALUE_STORE_TYPES(std::uint32_t)
TISSUE_VALUE_STORE_TYPES(std::int64_t)
TISSUE_VALUE_STORE_TYPES(std::uint64_t)
TISSUE_VALUE_STORE_TYPES(bool)
using CString = const char*;
TISSUE_VALUE_STORE_TYPES(CString)
#undef TISSUE_VALUE_STORE_TYPES

bool ValueStore::parameters_differ(const ValueStore& other) const {
  for (std::size_t k = 0; k < m_model->variables.size(); ++k) {
    const VariableInfo& info = m_model->variables[k];
    const Slot& s = m_slots[k];
    if (s.count == 0 || info.causality == Causality::input) continue;
    for (std::size_t e = s.offset; e < s.offset + s.count; ++e) {
      bool same = true;
      switch (storage_of(info.type)) {
        case Storage::float64:
          same = m_float64[e] == other.m_float64[e];
          break;
        case Storage::integer:
          same = m_integer[e] == other.m_integer[e];
          break;
        case Storage::uint64:
          same = m_uint64[e] == other.m_uint64[e];
          break;
        case Storage::string:
          same = m_string[e] == other.m_string[e];
          break;
      }
      if (!same) return true;
    }
  }
  return false;
}

void ValueStore::serialize(serial::ByteWriter& writer) const {
  writer.put(static_cast<std::uint64_t>(m_float64.size()));
  for (const double v : m_float64) writer.put(v);
  writer.put(static_cast<std::uint64_t>(m_integer.size()));
  for (const std::int64_t v : m_integer) writer.put(v);
  writer.put(static_cast<std::uint64_t>(m_uint64.size()));
  for (const std::uint64_t v : m_uint64) writer.put(v);
  writer.put(static_cast<std::uint64_t>(m_string.size()));
  for (const std::string& v : m_string) writer.put_string(v);
}

void ValueStore::deserialize(serial::ByteReader& reader) {
  const auto expect = [&](std::size_t size, std::size_t item_bytes) {
    if (reader.count(item_bytes) != size) serial::ByteReader::fail("the stored values are of another model");
  };
  std::vector<double> float64(m_float64.size());
  std::vector<std::int64_t> integer(m_integer.size());
  std::vector<std::uint64_t> uint64(m_uint64.size());
  std::vector<std::string> strings(m_string.size());
  expect(float64.size(), sizeof(double));
  for (double& v : float64) {
    reader.get(v);
    if (!std::isfinite(v)) serial::ByteReader::fail("a stored value is not finite");
  }
  expect(integer.size(), sizeof(std::int64_t));
  for (std::int64_t& v : integer) reader.get(v);
  expect(uint64.size(), sizeof(std::uint64_t));
  for (std::uint64_t& v : uint64) reader.get(v);
  expect(strings.size(), sizeof(std::uint64_t));
  for (std::string& v : strings) v = reader.get_string();
  // Check the schema's rules on a copy before taking the values: a refused state changes nothing.
  ValueStore candidate(*m_model);
  candidate.m_float64 = std::move(float64);
  candidate.m_integer = std::move(integer);
  candidate.m_uint64 = std::move(uint64);
  candidate.m_string = std::move(strings);
  for (const VariableInfo& info : m_model->variables) {
    if (info.is_stored()) candidate.check_rules(info);
  }
  *this = std::move(candidate);
}

}  // namespace tissue::fmi3
