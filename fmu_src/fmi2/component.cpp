// Component (see component.hpp).
#include "fmi2/component.hpp"

#include "fmi3/state_machine.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace tissue::fmi2 {

using fmi3::Status;
using fmi3::VariableError;
using fmi3::VariableType;

namespace {

constexpr std::size_t MAX_ELEMENTS = ScalarLayout::MAX_ELEMENTS;

// Calls `f` with a value of the C++ type the layer gets and sets an Integer variable of `type` as.
template <class F>
void with_integer_type(VariableType type, F&& f) {
  switch (type) {
    case VariableType::int32:
      f(std::int32_t{});
      break;
    case VariableType::uint32:
      f(std::uint32_t{});
      break;
    case VariableType::uint64:
      f(std::uint64_t{});
      break;
    default:  // int64, enumeration
      f(std::int64_t{});
  }
}

// A 2.0 Integer from a layer value, refused beyond fmi2Integer's range.
template <class V>
int to_integer(V value, const VariableInfo& info) {
  if (std::cmp_less(value, std::numeric_limits<int>::min()) ||
      std::cmp_greater(value, std::numeric_limits<int>::max())) {
    throw VariableError(std::string(info.name) + " = " + std::to_string(value) +
                        " does not fit an FMI 2.0 Integer (32 bits)");
  }
  return static_cast<int>(value);
}

template <class V>
V from_integer(int value, const VariableInfo& info) {
  if constexpr (std::is_unsigned_v<V>) {
    if (value < 0) throw VariableError(std::string(info.name) + " cannot be negative, got " + std::to_string(value));
  }
  return static_cast<V>(value);
}

}  // namespace

Component::Component(const ScalarLayout& layout, std::string name, std::string resource_path, bool logging_on,
                     fmi3::StatusLogger logger)
    : m_layout(layout),
      m_instance(layout.description(), std::move(name), std::move(resource_path), logging_on, std::move(logger)) {}

void Component::setup_experiment(double start_time_s) {
  if (!std::isfinite(start_time_s)) throw VariableError("fmi2SetupExperiment: the start time must be finite");
  m_start_time_s = start_time_s;
}

void Component::exit_initialization_mode() {
  flush_pending();
  m_instance.exit_initialization_mode();
}

Status Component::do_step(double current_time_s, double step_s) {
  flush_pending();
  return m_instance.do_step(current_time_s, step_s, m_last_successful_time_s);
}

void Component::reset() {
  m_pending.clear();
  m_instance.reset();
}

void Component::restore(const fmi3::InstanceState& saved) {
  m_instance.restore(saved);
  m_pending.clear();
}

const Scalar& Component::scalar(std::uint32_t vr, ScalarType expected) const {
  const Scalar* s = m_layout.find(vr);
  if (s == nullptr) throw VariableError("unknown value reference " + std::to_string(vr));
  const bool integer_like = expected == ScalarType::integer && s->type == ScalarType::enumeration;
  if (s->type != expected && !integer_like) {
    throw VariableError(s->name + " (value reference " + std::to_string(vr) + ") is a " +
                        std::string(to_string(s->type)) + ", not " + std::string(to_string(expected)));
  }
  return *s;
}

template <class T>
void Component::get(std::span<const std::uint32_t> vrs, std::span<T> values, ScalarType expected) {
  if (vrs.size() != values.size()) throw VariableError("the value references and values differ in number");
  if constexpr (std::is_same_v<T, const char*>) m_strings.clear();
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const Scalar& s = scalar(vrs[k], expected);
    const VariableInfo& info = *s.variable;
    const std::size_t n = ScalarLayout::element_count(info);
    const std::array<fmi3::ValueReference, 1> vr{info.vr};
    const auto pending = std::ranges::find(m_pending, &info, &Pending::variable);
    if constexpr (std::is_same_v<T, double>) {
      std::array<double, MAX_ELEMENTS> all{};
      if (pending != m_pending.end()) {
        std::ranges::copy(pending->values, all.begin());
      } else {
        m_instance.get<double>(vr, std::span(all.data(), n));
      }
      values[k] = all[s.element];
    } else if constexpr (std::is_same_v<T, const char*>) {
      std::array<const char*, 1> text{};
      m_instance.get<const char*>(vr, text);
      m_strings.emplace_back(text[0] == nullptr ? "" : text[0]);
    } else if (expected == ScalarType::boolean) {
      std::array<bool, MAX_ELEMENTS> all{};
      m_instance.get<bool>(vr, std::span(all.data(), n));
      values[k] = all[s.element] ? 1 : 0;
    } else {
      const auto pick = [&]<class V>(V) {
        std::array<V, MAX_ELEMENTS> all{};
        m_instance.get<V>(vr, std::span(all.data(), n));
        values[k] = to_integer(all[s.element], info);
      };
      with_integer_type(info.type, pick);
    }
  }
  if constexpr (std::is_same_v<T, const char*>) {
    for (std::size_t k = 0; k < values.size(); ++k) values[k] = m_strings[k].c_str();
  }
}

template <class T>
void Component::set(std::span<const std::uint32_t> vrs, std::span<const T> values, ScalarType expected) {
  if (vrs.size() != values.size()) throw VariableError("the value references and values differ in number");
  for (std::size_t k = 0; k < vrs.size(); ++k) {
    const Scalar& s = scalar(vrs[k], expected);
    const VariableInfo& info = *s.variable;
    const std::size_t n = ScalarLayout::element_count(info);
    const std::array<fmi3::ValueReference, 1> vr{info.vr};
    // The variable's other elements as they are (a non-stored variable is refused by the layer's set).
    const auto current = [&]<class V>(std::array<V, MAX_ELEMENTS>& all) {
      if (m_instance.values().holds(info)) m_instance.values().read<V>(info, std::span(all.data(), n));
    };
    if constexpr (std::is_same_v<T, double>) {
      std::array<double, MAX_ELEMENTS> all{};
      const auto pending = std::ranges::find(m_pending, &info, &Pending::variable);
      if (pending != m_pending.end()) {
        std::ranges::copy(pending->values, all.begin());
      } else {
        current(all);
      }
      all[s.element] = values[k];
      if (info.min_norm > 0.0) {
        double squared = 0.0;
        for (std::size_t e = 0; e < n; ++e) squared += all[e] * all[e];
        if (!(std::sqrt(squared) > info.min_norm) && std::isfinite(squared)) {
          // Not yet a value the layer takes: held, if the variable may be set now at all.
          if ((fmi3::variable_settable_states(info.causality, info.variability) & fmi3::mask(m_instance.state())) ==
              0) {
            m_instance.set<double>(vr, std::span<const double>(all.data(), n));  // refused, with the layer's reason
          }
          if (pending == m_pending.end()) {
            m_pending.push_back(
                {&info, std::vector<double>(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n))});
          } else {
            pending->values.assign(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n));
          }
          continue;
        }
      }
      m_instance.set<double>(vr, std::span<const double>(all.data(), n));
      if (pending != m_pending.end()) m_pending.erase(pending);
    } else if constexpr (std::is_same_v<T, const char*>) {
      if (values[k] == nullptr) throw VariableError(s.name + ": a null string");
      const std::array<const char*, 1> text{values[k]};
      m_instance.set<const char*>(vr, text);
    } else if (expected == ScalarType::boolean) {
      std::array<bool, MAX_ELEMENTS> all{};
      current(all);
      all[s.element] = values[k] != 0;
      m_instance.set<bool>(vr, std::span<const bool>(all.data(), n));
    } else {
      const auto patch = [&]<class V>(V) {
        std::array<V, MAX_ELEMENTS> all{};
        current(all);
        all[s.element] = from_integer<V>(values[k], info);
        m_instance.set<V>(vr, std::span<const V>(all.data(), n));
      };
      with_integer_type(info.type, patch);
    }
  }
}

void Component::flush_pending() {
  while (!m_pending.empty()) {
    const Pending pending = m_pending.back();
    m_pending.pop_back();
    const std::array<fmi3::ValueReference, 1> vr{pending.variable->vr};
    m_instance.set<double>(vr, pending.values);  // throws the layer's reason if it still fails
  }
}

template void Component::get<double>(std::span<const std::uint32_t>, std::span<double>, ScalarType);
template void Component::get<int>(std::span<const std::uint32_t>, std::span<int>, ScalarType);
template void Component::get<const char*>(std::span<const std::uint32_t>, std::span<const char*>, ScalarType);
template void Component::set<double>(std::span<const std::uint32_t>, std::span<const double>, ScalarType);
template void Component::set<int>(std::span<const std::uint32_t>, std::span<const int>, ScalarType);
template void Component::set<const char*>(std::span<const std::uint32_t>, std::span<const char* const>, ScalarType);

}  // namespace tissue::fmi2
