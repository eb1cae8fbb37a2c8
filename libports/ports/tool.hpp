// The tool as every part of the product sees it: the tool modes (the FMUs' ToolMode enumeration,
// the core's, the haptic loop's and the host's devices') and the tool axis of an orientation. Header
// only, plain C++20 and nothing else, so that the core, both FMUs and the host share one definition.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace tissue {

/// What the tool does: nothing (put away), a probe that pushes the surface, a scalpel that cuts.
/// The values are the FMUs' ToolMode enumeration items.
enum class ToolMode : std::int64_t { none = 0, probe = 1, scalpel = 2 };

struct ToolModeItem {
  ToolMode mode;
  std::string_view name;         ///< as in the FMUs' enumeration and the scenario files
  std::string_view description;  ///< the enumeration item's description
};

inline constexpr std::array<ToolModeItem, 3> TOOL_MODE_ITEMS{{
    {ToolMode::none, "none", "The tool is put away: it does not touch or cut the tissue, and no force is rendered"},
    {ToolMode::probe, "probe", "The tool tip pushes the surface (god-object contact); the contact force is rendered"},
    {ToolMode::scalpel, "scalpel", "The blade cuts the tissue; the cutting force is rendered"},
}};

/// The mode of a name ("none", "probe", "scalpel"), or nothing.
constexpr std::optional<ToolMode> tool_mode_named(std::string_view name) {
  for (const ToolModeItem& item : TOOL_MODE_ITEMS) {
    if (item.name == name) return item.mode;
  }
  return std::nullopt;
}

/// The mode of an enumeration value (0, 1, 2), or nothing.
constexpr std::optional<ToolMode> tool_mode_of(std::int64_t value) {
  for (const ToolModeItem& item : TOOL_MODE_ITEMS) {
    if (static_cast<std::int64_t>(item.mode) == value) return item.mode;
  }
  return std::nullopt;
}

/// The smallest norm an orientation quaternion (w, x, y, z) may have before it is normalized: the
/// core's pose check and the FMUs' orientation inputs (min_norm) refuse one at or below it.
inline constexpr double MIN_ORIENTATION_NORM = 1e-12;

/// The tool axis in world coordinates: the image of the tool's local +z axis (from the tip toward
/// the handle; the scalpel's edge runs along it) under the unit quaternion (w, x, y, z). The same
/// arithmetic as Eigen's q * Vector3d::UnitZ(), term by term, so both give the same bits.
constexpr std::array<double, 3> tool_axis(double w, double x, double y, double z) {
  return {2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)};
}

}  // namespace tissue
