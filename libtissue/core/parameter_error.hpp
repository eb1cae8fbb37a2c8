// The one error type for a parameter outside its range, shared by every folder of the core and by the
// haptic core (libtissue/haptic, which includes this leaf and links nothing of the core).
#pragma once

#include <cmath>
#include <stdexcept>
#include <string>

namespace tissue {

/// A parameter outside its physical range (E <= 0, nu outside [0, 0.5), h <= 0, ...).
class ParameterError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Throws ParameterError "<settings>.<setting> = <value>: must be <range>" unless `ok`.
inline void require_setting(const char* settings, bool ok, const char* setting, double value, const char* range) {
  if (!ok) {
    throw ParameterError(std::string(settings) + "." + setting + " = " + std::to_string(value) + ": must be " + range);
  }
}
/// require_setting for the two common ranges, each condition written once with its words.
inline void require_finite_non_negative(const char* settings, const char* setting, double value) {
  require_setting(settings, std::isfinite(value) && value >= 0.0, setting, value, "finite and >= 0");
}
inline void require_finite_positive(const char* settings, const char* setting, double value) {
  require_setting(settings, std::isfinite(value) && value > 0.0, setting, value, "finite and > 0");
}

}  // namespace tissue
