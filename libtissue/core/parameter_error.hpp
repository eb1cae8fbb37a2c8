// The one error type for a parameter outside its range, shared by every folder of the core and by the
// haptic core (libtissue/haptic, which includes this leaf and links nothing of the core).
#pragma once

#include <stdexcept>

namespace tissue {

/// A parameter outside its physical range (E <= 0, nu outside [0, 0.5), h <= 0, ...).
class ParameterError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

}  // namespace tissue
