// The names of an enumeration's values, written once beside the enumeration: the one vocabulary of
// the FMU's enumeration items, the scenario files, Python's keywords and the benches' options.
#pragma once

#include "core/parameter_error.hpp"

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>

namespace tissue {

/// One value's name and what it means.
struct NamedItem {
  std::string_view name;  ///< camelCase, as in the FMU's enumeration items
  std::string_view description;
};

/// "a, b or c" of the items' names.
inline std::string list_names(std::span<const NamedItem> items) {
  std::string text;
  for (std::size_t k = 0; k < items.size(); ++k) {
    if (k > 0) text += k + 1 == items.size() ? " or " : ", ";
    text += items[k].name;
  }
  return text;
}

/// The items of an enumeration E whose values are 0, 1, ..., N - 1 in this order (item k names value
/// k; the FMU numbers them from 1).
template <class E, std::size_t N>
struct ItemNames {
  std::string_view what;  ///< what the enumeration chooses, for messages ("linear solver")
  std::array<NamedItem, N> items;

  [[nodiscard]] constexpr std::string_view name(E value) const {
    return items.at(static_cast<std::size_t>(value)).name;
  }
  [[nodiscard]] constexpr std::span<const NamedItem> all() const { return items; }
  /// The value named `name`; throws ParameterError naming the accepted names.
  [[nodiscard]] E parse(std::string_view name) const {
    for (std::size_t k = 0; k < N; ++k) {
      if (items[k].name == name) return static_cast<E>(k);
    }
    throw ParameterError("unknown " + std::string(what) + " '" + std::string(name) + "' (expected " + names() + ")");
  }
  /// "a, b or c".
  [[nodiscard]] std::string names() const { return list_names(items); }
};

}  // namespace tissue
