// A structure-aware mutator for the Tissue FMU's serialized states (the state door): a flipped byte
// almost always fails the state's framing (tag, model, lengths), so plain mutations stop at
// deserialization. This one finds the tissue snapshot inside the FMU state (the last length-prefixed
// block before the two u64 counters, tissue_model.cpp), reads it with the core's own
// deserialize_snapshot, changes one field to a value at the edge of its range (a NaN displacement, a
// vector one longer, a cut naming a tet that does not exist, a batch end past the cuts, ...), and
// writes the FMU state around it again. Inputs it cannot read get libFuzzer's byte mutations.
#pragma once

#include <cstddef>
#include <cstdint>

namespace tissue::fuzz {

std::size_t mutate_state(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned int seed);

}  // namespace tissue::fuzz
