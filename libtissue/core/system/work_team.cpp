// WorkTeam (see work_team.hpp).
#include "core/system/work_team.hpp"

#include "core/parameter_error.hpp"

#include <pthread.h>
#include <sched.h>

#include <chrono>
#include <string>

namespace tissue {
namespace {

// How long a waiting member spins before it blocks: longer than the gaps between a step's jobs
// (the serial work between two CG phases, a few microseconds), because waking a blocked thread
// costs tens of microseconds on a virtual machine (its core halts and needs an interrupt), and
// short enough that members sharing a core lose little.
constexpr std::chrono::microseconds SPIN_TIME{100};
constexpr int POLLS_PER_CLOCK_READ = 64;

// Waits until `value` differs from `old`: spins (pause between polls) for up to SPIN_TIME, then
// blocks on the atomic (a futex), so that a member whose partner shares its core (a busy machine,
// a new thread placed on its parent's core) gives the core up instead of spinning to the end of
// its time slice: spinning with yield() alone made 40 hand-overs take 4-40 ms there.
template <class T>
void wait_while_equal(const std::atomic<T>& value, T old) {
  const auto give_up = std::chrono::steady_clock::now() + SPIN_TIME;
  for (int polls = 1;; ++polls) {
    if (value.load(std::memory_order_acquire) != old) return;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
    if (polls % POLLS_PER_CLOCK_READ == 0 && std::chrono::steady_clock::now() > give_up) break;
  }
  while (value.load(std::memory_order_acquire) == old) value.wait(old, std::memory_order_acquire);
}

// Keeps a new worker off the caller's current core when the caller may run on others. Left to
// itself, Linux often started the worker next to its parent on this machine (a 2-core VM) and kept
// it there, step after step, while the other core idled: the members then took turns on one core
// (the frog's two-thread step 7.8 ms instead of 0.38 in about one run of three). Best effort: the
// caller's own affinity is left alone, and a failure only loses the hint.
void keep_off_callers_core(std::thread& worker) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0) return;
  const int current = sched_getcpu();
  if (current < 0 || current >= CPU_SETSIZE || !CPU_ISSET(current, &allowed) || CPU_COUNT(&allowed) < 2) return;
  CPU_CLR(current, &allowed);
  pthread_setaffinity_np(worker.native_handle(), sizeof allowed, &allowed);
}

}  // namespace

void validate_step_threads(int threads) {
  if (threads < 1 || threads > MAX_STEP_THREADS) {
    throw ParameterError("threads must be 1 to " + std::to_string(MAX_STEP_THREADS) +
                         " (the assembly splits the mesh in two), got " + std::to_string(threads));
  }
}

WorkTeam::WorkTeam(int threads) : m_size(threads) {
  validate_step_threads(threads);
  static_assert(MAX_STEP_THREADS < static_cast<int>(PART_SLOTS), "a job's parts fit in its slots");
  m_workers.reserve(static_cast<size_t>(threads - 1));
  for (int member = 1; member < threads; ++member) {
    m_workers.emplace_back([this] { work(); });
    keep_off_callers_core(m_workers.back());
  }
}

WorkTeam::~WorkTeam() {
  m_stop.store(true, std::memory_order_release);
  // A new generation with no part to claim: the workers wake, see the stop and return.
  const std::uint64_t generation = m_job.load(std::memory_order_relaxed) / PART_SLOTS + 1;
  m_job.store(generation * PART_SLOTS + static_cast<std::uint64_t>(m_size), std::memory_order_release);
  m_job.notify_all();
  for (std::thread& worker : m_workers) worker.join();
}

int WorkTeam::run_claimed_parts(std::uint64_t generation) {
  int ran = 0;
  std::uint64_t job = m_job.load(std::memory_order_acquire);
  while (job / PART_SLOTS == generation && job % PART_SLOTS < static_cast<std::uint64_t>(m_size)) {
    if (!m_job.compare_exchange_weak(job, job + 1, std::memory_order_acq_rel, std::memory_order_acquire)) continue;
    // Claimed: the job cannot end (nor m_context change) before this part reports done.
    m_trampoline(m_context, static_cast<int>(job % PART_SLOTS));
    ++ran;
    m_parts_done.fetch_add(1, std::memory_order_acq_rel);
    m_parts_done.notify_all();
    job = m_job.load(std::memory_order_acquire);
  }
  return ran;
}

void WorkTeam::run_erased(void* context, Trampoline trampoline) {
  if (m_size == 1) {
    trampoline(context, 0);
    return;
  }
  m_context = context;
  m_trampoline = trampoline;
  m_parts_done.store(0, std::memory_order_relaxed);
  const std::uint64_t generation = m_job.load(std::memory_order_relaxed) / PART_SLOTS + 1;
  m_job.store(generation * PART_SLOTS + 1, std::memory_order_release);  // publishes the job; part 0 is ours
  m_job.notify_all();
  trampoline(context, 0);
  m_parts_taken_over += run_claimed_parts(generation);
  for (int done = m_parts_done.load(std::memory_order_acquire); done != m_size - 1;
       done = m_parts_done.load(std::memory_order_acquire)) {
    wait_while_equal(m_parts_done, done);
  }
}

void WorkTeam::work() {
  std::uint64_t seen = 0;  // the generation of the last job this worker looked at
  for (;;) {
    std::uint64_t job = m_job.load(std::memory_order_acquire);
    while (job / PART_SLOTS == seen) {
      wait_while_equal(m_job, job);
      job = m_job.load(std::memory_order_acquire);
    }
    if (m_stop.load(std::memory_order_acquire)) return;
    seen = job / PART_SLOTS;
    run_claimed_parts(seen);
  }
}

}  // namespace tissue
