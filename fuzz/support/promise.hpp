// What a fuzz target asserts: the product's promise for one door (fuzz/README.md). A broken promise
// aborts with what broke, so that libFuzzer keeps the input as a crash.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

namespace tissue::fuzz {

[[noreturn]] inline void broken(const char* promise, std::string_view detail = {}) {
  std::fprintf(stderr, "fuzz: promise broken: %s %.*s\n", promise, static_cast<int>(detail.size()), detail.data());
  std::abort();
}

/// Refused inputs must say why.
inline void require_message(std::string_view what, const char* door) {
  if (what.empty()) broken("refused without a message:", door);
}

/// A hand pose a device hands the haptic thread: a finite position and a unit quaternion (to
/// `quaternion_tolerance` in its squared norm: what the decoder's arithmetic leaves).
template <class Pose>
void require_usable_pose(const Pose& pose, double quaternion_tolerance, const char* door) {
  double norm_squared = 0.0;
  for (const double q : pose.orientation_wxyz) norm_squared += q * q;
  for (const double x : pose.position_m) {
    if (!std::isfinite(x)) broken("a pose accepted with a non-finite position:", door);
  }
  if (!(std::abs(norm_squared - 1.0) < quaternion_tolerance)) broken("a pose accepted without a unit quaternion:", door);
}

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace tissue::fuzz
