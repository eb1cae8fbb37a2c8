// The real-time memory recipe (host/schedule/memory_reserve.hpp, issue 42): after keep_freed_memory()
// and touch_heap(), what a thread allocates and writes within the touched size lands on pages it
// already has: no page fault. Counted with the thread's minor page faults (getrusage), not timed.
// Run in a thread of its own (its own heap). Not under a sanitizer: ASan's allocator ignores mallopt.
#include "schedule/memory_reserve.hpp"
#include "support/under_sanitizer.hpp"

#include <gtest/gtest.h>

#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <thread>

namespace tissue::host {
namespace {

long minor_faults_of_this_thread() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_minflt;
}

// Minor page faults of a thread that allocates `bytes`, writes them, frees them, after `prepare`.
template <class Prepare>
long faults_of_a_block(std::size_t bytes, Prepare prepare) {
  long faults = -1;
  std::thread([&] {
    prepare();
    const long before = minor_faults_of_this_thread();
    void* block = std::malloc(bytes);
    ASSERT_NE(block, nullptr);
    std::memset(block, 1, bytes);
    std::free(block);
    faults = minor_faults_of_this_thread() - before;
  }).join();
  return faults;
}

TEST(MemoryReserve, ABlockWithinTheTouchedHeapTakesNoNewPage) {
  if (test::UNDER_SANITIZER) GTEST_SKIP() << "the sanitizer's allocator ignores mallopt";
  constexpr std::size_t BLOCK = std::size_t{8} << 20;  // the organ's re-mesh: a few MB
  const auto pages = static_cast<long>(BLOCK / static_cast<std::size_t>(sysconf(_SC_PAGESIZE)));
  // Without the reserve the block's pages are new: one fault each (a mapping of its own).
  const long fresh = faults_of_a_block(BLOCK, [] {});
  EXPECT_GT(fresh, pages / 2);
  keep_freed_memory();
  const long reserved = faults_of_a_block(BLOCK, [] { touch_heap(DYNAMICS_HEAP_RESERVE_BYTES); });
  EXPECT_LT(reserved, pages / 100) << "of " << pages << " pages; " << fresh << " without the reserve";
}

}  // namespace
}  // namespace tissue::host
