// A structure-aware mutator for TOML inputs (the scenario door): plain byte mutations rarely keep a
// scenario parseable, so most inputs would stop at the TOML parser. This one parses the input with
// toml++, changes one node (a value to a boundary value, another type, a key deleted, copied under
// another name, an array element dropped or repeated, a string's bytes mutated) and prints the table
// again. Inputs that do not parse get libFuzzer's byte mutations.
#pragma once

#include <cstddef>
#include <cstdint>

namespace tissue::fuzz {

std::size_t mutate_toml(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned int seed);

}  // namespace tissue::fuzz
