// WorkTeam: the opt-in second (third, ...) thread of one step. A team is made at the start of a
// step and joined at its end (it never outlives the step that made it: no pool lingers between
// steps, inside an FMU or anywhere else); within the step its members run jobs side by side and
// wait for each other by spinning for up to 100 us (a hand-over then costs ~1 us instead of a
// blocked thread's wake-up, tens of us on a virtual machine), then by blocking, so that members
// sharing a core never spin away each other's time slice.
#pragma once

#include <atomic>
#include <thread>
#include <vector>

namespace tissue {

/// The most threads a step may use: the assembly splits the mesh in two (CorotationalElasticity).
inline constexpr int MAX_STEP_THREADS = 2;

/// Throws ParameterError unless 1 <= threads <= MAX_STEP_THREADS: the one check of a thread setting.
void validate_step_threads(int threads);

class WorkTeam {
 public:
  /// Starts `threads - 1` workers (the caller is member 0). Throws ParameterError unless
  /// validate_step_threads(threads) accepts it.
  explicit WorkTeam(int threads);
  /// Stops and joins the workers.
  ~WorkTeam();
  WorkTeam(const WorkTeam&) = delete;
  WorkTeam& operator=(const WorkTeam&) = delete;

  [[nodiscard]] int size() const { return m_size; }

  /// Runs job(member) for every member 0 .. size() - 1 (member 0 on the calling thread) and returns
  /// when all have finished. The job must not throw (the core's jobs are arithmetic on buffers that
  /// exist already); one that does terminates the program, as in any thread.
  template <class Job>
  void run(Job& job) {
    run_erased(&job, [](void* context, int member) { (*static_cast<Job*>(context))(member); });
  }

 private:
  using Trampoline = void (*)(void*, int);
  void run_erased(void* context, Trampoline trampoline);
  void work(int member);

  int m_size = 1;
  std::vector<std::thread> m_workers;
  void* m_context = nullptr;
  Trampoline m_trampoline = nullptr;
  std::atomic<unsigned> m_generation{0};  // bumped for each job; workers start when it changes
  std::atomic<int> m_finished{0};         // workers done with the current job
  std::atomic<bool> m_stop{false};
};

/// The parts a pass over a step's data is split into with `team` (nullptr: none): its size, else 1.
[[nodiscard]] inline int team_parts(const WorkTeam* team) { return team != nullptr ? team->size() : 1; }

/// job(part) for every part 0 .. parts - 1: side by side on `team` when it has `parts` members,
/// else one after another on the calling thread. A job that writes per-part results and combines
/// them in part order gives bitwise the same with a team or without.
template <class Job>
void run_parts(WorkTeam* team, int parts, Job&& job) {
  if (team != nullptr && team->size() == parts && parts > 1) {
    team->run(job);
  } else {
    for (int part = 0; part < parts; ++part) job(part);
  }
}

}  // namespace tissue
