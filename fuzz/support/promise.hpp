// What a fuzz target asserts: the product's promise for one door (fuzz/README.md). A broken promise
// aborts with what broke, so that libFuzzer keeps the input as a crash.
#pragma once

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

inline std::string_view as_text(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace tissue::fuzz
