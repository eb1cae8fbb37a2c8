// keep_freed_memory, touch_heap (see memory_reserve.hpp).
#include "schedule/memory_reserve.hpp"

#include <malloc.h>
#include <unistd.h>

#include <cstdlib>

namespace tissue::host {

void keep_freed_memory() {
  (void)mallopt(M_TRIM_THRESHOLD, -1);  // never give the heap's top back
  (void)mallopt(M_MMAP_MAX, 0);         // no block in a mapping of its own (unmapped when freed)
}

void touch_heap(std::size_t bytes) {
  auto* block = static_cast<volatile char*>(std::malloc(bytes));
  if (block == nullptr) return;  // no reserve: the session runs, with page faults
  const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  for (std::size_t i = 0; i < bytes; i += page) block[i] = 0;
  std::free(const_cast<char*>(block));
}

}  // namespace tissue::host
