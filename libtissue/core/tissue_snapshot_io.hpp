// Serializing a TissueSnapshot to bytes and back (FMI's SerializeFMUState / DeSerializeFMUState).
// The format is the project's own: a magic tag and version, then the fields in a fixed order,
// little-endian as the x86-64 machines the FMU is built for. Reading checks every length against
// the bytes left and refuses a malformed or truncated buffer with a StateError.
#pragma once

#include "core/tissue.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace tissue {

std::vector<std::uint8_t> serialize_snapshot(const TissueSnapshot& snapshot);

/// Throws StateError for bytes that are not a whole snapshot of this format.
TissueSnapshot deserialize_snapshot(std::span<const std::uint8_t> bytes);

}  // namespace tissue
