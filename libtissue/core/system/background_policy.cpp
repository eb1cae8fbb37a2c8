// leave_realtime_policy (see background_policy.hpp).
#include "core/system/background_policy.hpp"

#include <pthread.h>
#include <sched.h>

namespace tissue {

void leave_realtime_policy() noexcept {
  int policy = SCHED_OTHER;
  sched_param parameters{};
  if (pthread_getschedparam(pthread_self(), &policy, &parameters) != 0) return;
  if (policy != SCHED_FIFO && policy != SCHED_RR) return;
  parameters.sched_priority = 0;
  (void)pthread_setschedparam(pthread_self(), SCHED_OTHER, &parameters);
}

void lend_realtime_policy(pthread_t thread) noexcept {
  int policy = SCHED_OTHER;
  sched_param parameters{};
  if (pthread_getschedparam(pthread_self(), &policy, &parameters) != 0) return;
  if (policy != SCHED_FIFO && policy != SCHED_RR) return;
  (void)pthread_setschedparam(thread, policy, &parameters);
}

}  // namespace tissue
