// WorkTeam (see work_team.hpp).
#include "core/system/work_team.hpp"

#include "core/parameter_error.hpp"

#include <string>

namespace tissue {
namespace {

// Polls before a waiting member blocks: ~10-20 us, several times a job's hand-over on a free core.
constexpr int SPIN_POLLS = 2000;

// Waits until `value` differs from `old`: spins (pause between polls), then blocks on the atomic
// (a futex), so that a member whose partner shares its core (a busy or oversubscribed machine, a
// new thread placed on its parent's core) gives the core up instead of spinning to the end of its
// time slice: spinning with yield() alone made 40 hand-overs take 4-40 ms there.
template <class T>
void wait_while_equal(const std::atomic<T>& value, T old) {
  for (int polls = 0; polls < SPIN_POLLS; ++polls) {
    if (value.load(std::memory_order_acquire) != old) return;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  while (value.load(std::memory_order_acquire) == old) value.wait(old, std::memory_order_acquire);
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
  m_workers.reserve(static_cast<size_t>(threads - 1));
  for (int member = 1; member < threads; ++member) m_workers.emplace_back([this, member] { work(member); });
}

WorkTeam::~WorkTeam() {
  m_stop.store(true, std::memory_order_release);
  m_generation.fetch_add(1, std::memory_order_acq_rel);
  m_generation.notify_all();
  for (std::thread& worker : m_workers) worker.join();
}

void WorkTeam::run_erased(void* context, Trampoline trampoline) {
  if (m_size == 1) {
    trampoline(context, 0);
    return;
  }
  m_context = context;
  m_trampoline = trampoline;
  m_finished.store(0, std::memory_order_relaxed);
  m_generation.fetch_add(1, std::memory_order_acq_rel);  // publishes the job to the workers
  m_generation.notify_all();
  trampoline(context, 0);
  for (int finished = m_finished.load(std::memory_order_acquire); finished != m_size - 1;
       finished = m_finished.load(std::memory_order_acquire)) {
    wait_while_equal(m_finished, finished);
  }
}

void WorkTeam::work(int member) {
  unsigned seen = 0;
  for (;;) {
    wait_while_equal(m_generation, seen);
    seen = m_generation.load(std::memory_order_acquire);
    if (m_stop.load(std::memory_order_acquire)) return;
    m_trampoline(m_context, member);
    m_finished.fetch_add(1, std::memory_order_acq_rel);
    m_finished.notify_one();
  }
}

}  // namespace tissue
