// Replaces the global operator new/delete of one test or benchmark executable with versions that
// count the allocations and the bytes asked for (g_allocations, g_allocated_bytes). Include it in
// exactly one translation unit of an executable: it defines the replacement operators.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

inline std::atomic<long> g_allocations{0};
inline std::atomic<std::size_t> g_allocated_bytes{0};

// GCC sees free() on memory from operator new and warns; here both sides are ours (malloc/free).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  g_allocated_bytes.fetch_add(size, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop
