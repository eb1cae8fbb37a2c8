// leave_realtime_policy, lend_realtime_policy (see background_policy.hpp).
#include "core/system/background_policy.hpp"

#include <pthread.h>
#include <sched.h>

namespace tissue {
namespace {

// Whether the calling thread runs at a real-time policy (SCHED_FIFO or SCHED_RR); its policy and
// parameters then.
bool caller_realtime_policy(int& policy, sched_param& parameters) noexcept {
  return pthread_getschedparam(pthread_self(), &policy, &parameters) == 0 &&
         (policy == SCHED_FIFO || policy == SCHED_RR);
}

}  // namespace

void leave_realtime_policy() noexcept {
  int policy = SCHED_OTHER;
  sched_param parameters{};
  if (!caller_realtime_policy(policy, parameters)) return;
  parameters.sched_priority = 0;
  (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &parameters);
}

void lend_realtime_policy(pthread_t thread) noexcept {
  int policy = SCHED_OTHER;
  sched_param parameters{};
  if (!caller_realtime_policy(policy, parameters)) return;
  (void)pthread_setschedparam(thread, policy, &parameters);
}

}  // namespace tissue
