// set_thread_nice (host/sync/realtime_clock.hpp): a real-time run lowers the frame writer's thread
// (issue 42) and nothing else, so the nice value must be the calling thread's alone (Linux keeps one
// per thread), read back with getpriority on the thread's id (thread_nice).
#include "sync/realtime_clock.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace tissue::host {
namespace {

TEST(ThreadNice, LowersTheCallingThreadOnly) {
  const int before = thread_nice();
  int in_thread = before;
  bool set = false;
  std::thread([&] {
    set = set_thread_nice(before + 3 <= 19 ? before + 3 : 19);
    in_thread = thread_nice();
  }).join();
  ASSERT_TRUE(set);
  EXPECT_EQ(in_thread, before + 3 <= 19 ? before + 3 : 19);
  EXPECT_EQ(thread_nice(), before);
}

}  // namespace
}  // namespace tissue::host
