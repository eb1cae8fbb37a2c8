// The FMU-state calls as both C ABIs make them (fmi3_functions.cpp, fmi2/fmi2_functions.cpp): an
// importer's state handle is an InstanceState the instance saved, owned by the importer until it
// frees it. Each throws VariableError for a null pointer or a buffer of the wrong size; the
// caller runs it under Instance::run.
#pragma once

#include "fmi3/instance.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace tissue::fmi3 {

/// Saves the instance into `*state` (a state already there is overwritten, as the standard says).
inline void get_fmu_state(const Instance& instance, void** state) {
  if (state == nullptr) throw VariableError("the state pointer is null");
  std::unique_ptr<InstanceState> saved = instance.save();
  delete static_cast<InstanceState*>(*state);
  *state = saved.release();
}

inline void set_fmu_state(Instance& instance, const void* state) {
  if (state == nullptr) throw VariableError("the state is null");
  instance.restore(*static_cast<const InstanceState*>(state));
}

inline void free_fmu_state(void** state) {
  if (state == nullptr) return;
  delete static_cast<InstanceState*>(*state);
  *state = nullptr;
}

inline std::size_t serialized_fmu_state_size(const Instance& instance, const void* state) {
  if (state == nullptr) throw VariableError("the state is null");
  return instance.serialize(*static_cast<const InstanceState*>(state)).size();
}

/// `size` must be what serialized_fmu_state_size() said (`size_function` names it in the message).
inline void serialize_fmu_state(const Instance& instance, const void* state, void* buffer, std::size_t size,
                                const char* size_function) {
  if (state == nullptr) throw VariableError("the state is null");
  const std::vector<std::uint8_t> bytes = instance.serialize(*static_cast<const InstanceState*>(state));
  if (size != bytes.size() || (size > 0 && buffer == nullptr)) {
    throw VariableError("the buffer holds " + std::to_string(size) + " bytes, the state needs " +
                        std::to_string(bytes.size()) + " (" + size_function + ")");
  }
  std::copy(bytes.begin(), bytes.end(), static_cast<std::uint8_t*>(buffer));
}

inline void deserialize_fmu_state(const Instance& instance, const void* bytes, std::size_t size, void** state) {
  if (state == nullptr) throw VariableError("the state pointer is null");
  if (size > 0 && bytes == nullptr) throw VariableError("a null array was passed with a non-zero length");
  std::unique_ptr<InstanceState> saved =
      instance.deserialize(std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(bytes), size));
  delete static_cast<InstanceState*>(*state);
  *state = saved.release();
}

}  // namespace tissue::fmi3
