// Whether a test runs in a sanitizer build (the asan and tsan presets): long cases shrink there, and
// say so. The one place the tests detect it.
#pragma once

namespace tissue::test {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool UNDER_SANITIZER = true;
#else
inline constexpr bool UNDER_SANITIZER = false;
#endif

}  // namespace tissue::test
