// reserve_resident: room reserved in a vector and written once, so that its pages are resident
// before a step or a re-mesh needs them. Growing a vector inside a real-time slot costs a copy of
// what it holds and a page fault per fresh page (on the 2-core VM several microseconds each): the
// render surface's first split points re-allocated its 41k-point arrays (12 ms of the organ's
// first cut). Where nobody locks memory (Python, an FMU importer) the written pages stay mapped;
// tissue-host's mlockall locks them with the rest.
#pragma once

#include <cstddef>
#include <vector>

namespace tissue {

/// Capacity for at least `capacity` elements, its pages written (sized up and back: a vector keeps
/// its capacity when it shrinks). Leaves the elements as they were; does nothing if the room is there.
template <class T>
void reserve_resident(std::vector<T>& values, std::size_t capacity) {
  if (values.capacity() >= capacity) return;
  values.reserve(capacity);
  const std::size_t size = values.size();
  values.resize(values.capacity());
  values.resize(size);
}

}  // namespace tissue
