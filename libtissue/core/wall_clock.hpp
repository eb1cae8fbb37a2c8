// Wall-clock time for the step reports' parts (steady clock, seconds).
#pragma once

#include <chrono>

namespace tissue {

/// Seconds of the steady clock since `start`.
inline double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace tissue
