// The host's clocks and real-time priority (see realtime_clock.hpp).
#include "sync/realtime_clock.hpp"

#include <pthread.h>
#include <sched.h>
#include <time.h>

#include <cerrno>
#include <cmath>
#include <cstring>

namespace tissue::host {

Nanoseconds now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<Nanoseconds>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

void sleep_until_ns(Nanoseconds deadline) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadline % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

Nanoseconds thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<Nanoseconds>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

Nanoseconds to_ns(double seconds) { return static_cast<Nanoseconds>(std::llround(seconds * 1e9)); }

Priority try_fifo_priority(int priority) {
  sched_param param{};
  param.sched_priority = priority;
  const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
  if (error == 0) return {true, "SCHED_FIFO"};
  return {false, std::string("real-time priority not permitted (") + std::strerror(error) +
                     "): running at normal priority; run as root, or grant rtprio in /etc/security/limits.conf "
                     "or CAP_SYS_NICE"};
}

}  // namespace tissue::host
