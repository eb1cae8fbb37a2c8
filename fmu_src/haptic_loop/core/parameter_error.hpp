// The error the haptic core throws for a setting outside its range. The FMU layer delegates every
// range check of the HapticLoop's parameters to the validate() functions that throw it.
#pragma once

#include <stdexcept>

namespace tissue::haptic {

/// A renderer setting outside its range; what() names the setting and the value.
class ParameterError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace tissue::haptic
