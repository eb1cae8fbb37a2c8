// fmu3_library.cpp - dlopen/dlsym of an FMI 3.0 FMU binary.
#include "importer/fmu3_library.hpp"

#include "fmi3_function_names.hpp"
#include "importer/fmu_error.hpp"

#include <dlfcn.h>

#include <array>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace tissue::host {
namespace {

#define TISSUE_FMI3_NAME_STRING(name) #name,
/// The names of the members of Fmu3Functions, in declaration order.
constexpr std::array LOADED_FUNCTION_NAMES = {TISSUE_FMI3_FOR_EACH_FUNCTION(TISSUE_FMI3_NAME_STRING)};
#undef TISSUE_FMI3_NAME_STRING

constexpr bool same_names() {
  if (LOADED_FUNCTION_NAMES.size() != fmi3::FMI3_FUNCTION_NAMES.size()) {
    return false;
  }
  for (std::size_t i = 0; i < LOADED_FUNCTION_NAMES.size(); ++i) {
    if (std::string_view(LOADED_FUNCTION_NAMES[i]) != fmi3::FMI3_FUNCTION_NAMES[i]) {
      return false;
    }
  }
  return true;
}
static_assert(same_names(), "TISSUE_FMI3_FOR_EACH_FUNCTION must list FMI3_FUNCTION_NAMES in the same order");

/// The last dlerror() text, or a placeholder.
std::string last_dl_error() {
  const char* text = dlerror();
  return text == nullptr ? std::string("unknown dlopen error") : std::string(text);
}

}  // namespace

Fmu3Library::Fmu3Library(const std::filesystem::path& binary_path) : m_path(binary_path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(binary_path, error)) {
    throw FmuError("FMU binary '" + binary_path.string() + "' does not exist (the FMU provides no binary for " +
                   "this platform, or its modelIdentifier does not match the file name)");
  }
  m_handle = dlopen(binary_path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (m_handle == nullptr) {
    throw FmuError("cannot load FMU binary '" + binary_path.string() + "': " + last_dl_error());
  }

  std::vector<std::string_view> missing;
  // POSIX guarantees that a dlsym result converts to a function pointer (dlsym rationale).
#define TISSUE_FMI3_RESOLVE(name)                                           \
  m_functions.name = reinterpret_cast<name##TYPE*>(dlsym(m_handle, #name)); \
  if (m_functions.name == nullptr) {                                        \
    missing.emplace_back(#name);                                            \
  }
  TISSUE_FMI3_FOR_EACH_FUNCTION(TISSUE_FMI3_RESOLVE)
#undef TISSUE_FMI3_RESOLVE

  if (!missing.empty()) {
    std::string list;
    for (const std::string_view name : missing) {
      list += (list.empty() ? "" : ", ") + std::string(name);
    }
    close();
    throw FmuError("FMU binary '" + binary_path.string() + "' does not export " + std::to_string(missing.size()) +
                   " of the " + std::to_string(fmi3::FMI3_FUNCTION_NAMES.size()) + " FMI 3.0 functions: " + list);
  }
}

Fmu3Library::~Fmu3Library() { close(); }

Fmu3Library::Fmu3Library(Fmu3Library&& other) noexcept
    : m_path(std::move(other.m_path)),
      m_handle(std::exchange(other.m_handle, nullptr)),
      m_functions(std::exchange(other.m_functions, {})) {}

Fmu3Library& Fmu3Library::operator=(Fmu3Library&& other) noexcept {
  if (this != &other) {
    close();
    m_path = std::move(other.m_path);
    m_handle = std::exchange(other.m_handle, nullptr);
    m_functions = std::exchange(other.m_functions, {});
  }
  return *this;
}

void Fmu3Library::close() noexcept {
  if (m_handle != nullptr) {
    dlclose(m_handle);
    m_handle = nullptr;
    m_functions = {};
  }
}

}  // namespace tissue::host
