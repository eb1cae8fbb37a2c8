// An int index (the mesh's and the matrix's numbering) as a container's size_t index.
#pragma once

#include <cstddef>

namespace tissue {

/// `index` as std::size_t; the caller knows it is >= 0.
constexpr std::size_t to_size(int index) { return static_cast<std::size_t>(index); }

}  // namespace tissue
