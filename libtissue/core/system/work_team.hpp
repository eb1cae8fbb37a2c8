// WorkTeam: the opt-in second (third, ...) thread of one step. A team is made at the start of a
// step and joined at its end (it never outlives the step that made it: no pool lingers between
// steps, inside an FMU or anywhere else); within the step its members run jobs side by side and
// wait for each other by spinning for up to 100 us (a hand-over then costs ~1 us instead of a
// blocked thread's wake-up, tens of us on a virtual machine), then by blocking, so that members
// sharing a core never spin away each other's time slice.
//
// A job's parts are claimed, not assigned: the caller runs part 0, then every part no worker has
// started yet, and waits only for parts a worker is running. A worker the scheduler has not run
// yet (preempted by the haptic thread, waking from a block) therefore never holds the step up; it
// finds the job done when it comes. Each part is the same computation whoever runs it, so the
// results stay bitwise those of one thread.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
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
  /// Parts the caller ran because no worker had started them (since the team was made).
  [[nodiscard]] long parts_taken_over() const { return m_parts_taken_over; }

  /// Runs job(part) for every part 0 .. size() - 1 and returns when all have finished: part 0 on the
  /// calling thread, each other part on the first member to claim it (a worker, or the caller once
  /// it is done with its own). The parts must not wait for each other. The job must not throw (the
  /// core's jobs are arithmetic on buffers that exist already); one that does terminates the
  /// program, as in any thread.
  template <class Job>
  void run(Job& job) {
    run_erased(&job, [](void* context, int member) { (*static_cast<Job*>(context))(member); });
  }

 private:
  using Trampoline = void (*)(void*, int);
  void run_erased(void* context, Trampoline trampoline);
  void work();
  /// Claims and runs parts of job `generation` until none is left; returns how many it ran.
  int run_claimed_parts(std::uint64_t generation);

  int m_size = 1;
  std::vector<std::thread> m_workers;
  void* m_context = nullptr;
  Trampoline m_trampoline = nullptr;
  // The current job: its generation (bumped for each job; workers start when it changes) times
  // PART_SLOTS plus the next part to claim. One word, so that a late worker can claim a part only
  // of the job it saw, never of one published since.
  static constexpr std::uint64_t PART_SLOTS = 256;
  std::atomic<std::uint64_t> m_job{0};
  std::atomic<int> m_parts_done{0};  // parts 1 .. size() - 1 of the current job finished
  std::atomic<bool> m_stop{false};
  long m_parts_taken_over = 0;
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

/// job(phase, part) for every part of `phases` phases of MAX_STEP_THREADS parts each, a phase's
/// parts side by side on `team`, phase after phase (the assembly's conflict-free halves); returns
/// the sum of what the parts return, added phase by phase in part order: bitwise the same with a
/// team or without.
template <class Job>
double sum_over_phases(WorkTeam* team, int phases, Job&& job) {
  double sum = 0.0;
  for (int phase = 0; phase < phases; ++phase) {
    std::array<double, MAX_STEP_THREADS> part_sum{};
    run_parts(team, MAX_STEP_THREADS, [&](int part) { part_sum[static_cast<std::size_t>(part)] = job(phase, part); });
    for (const double part : part_sum) sum += part;
  }
  return sum;
}

}  // namespace tissue
