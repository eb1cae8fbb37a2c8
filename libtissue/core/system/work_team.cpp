// WorkTeam (see work_team.hpp).
#include "core/system/work_team.hpp"

#include "core/parameter_error.hpp"

#include <string>

namespace tissue {
namespace {

// A spinning wait: pause (x86) between polls; after many polls, yield, so that a team on a
// machine with fewer free cores than members still makes progress.
template <class Done>
void spin_until(Done done) {
  for (int polls = 0; !done(); ++polls) {
    if (polls < 20000) {
#if defined(__x86_64__) || defined(__i386__)
      __builtin_ia32_pause();
#endif
    } else {
      std::this_thread::yield();
    }
  }
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
  trampoline(context, 0);
  spin_until([&] { return m_finished.load(std::memory_order_acquire) == m_size - 1; });
}

void WorkTeam::work(int member) {
  unsigned seen = 0;
  for (;;) {
    spin_until([&] { return m_generation.load(std::memory_order_acquire) != seen; });
    seen = m_generation.load(std::memory_order_acquire);
    if (m_stop.load(std::memory_order_acquire)) return;
    m_trampoline(m_context, member);
    m_finished.fetch_add(1, std::memory_order_acq_rel);
  }
}

}  // namespace tissue
