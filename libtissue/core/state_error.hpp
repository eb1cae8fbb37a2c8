// The one error type for a saved state that cannot be restored, shared by the facade and its parts.
#pragma once

#include <stdexcept>

namespace tissue {

/// A saved state that cannot be restored here (another model, a malformed or inconsistent state).
class StateError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tissue
