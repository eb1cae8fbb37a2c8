// BackgroundWork: one job at a time on a thread of its own, at the operating system's normal
// priority (SCHED_OTHER), whatever the priority of the thread that hands it over
// (core/system/background_policy.hpp): a real-time importer's or tissue-host's threads run at
// SCHED_FIFO and take their cores whenever they want them, so the job uses only the time they leave
// idle and never delays them; while the owner waits for it, at the owner's priority (a real-time
// owner lends it its policy: background_policy.hpp). The one mechanism for work beside the steps:
// the Tissue FMU's surface prepared after a cut (docs/DESIGN.md, "The surface is prepared after a
// cut"), the contact stiffness K_c (BackgroundContactStiffness) and the lagged Cholesky factor's
// refactorization (CholeskyPcgSolver). The thread is made at the first job and lives until
// destruction. Not thread-safe: one owner calls start() and wait().
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace tissue {

class BackgroundWork {
 public:
  BackgroundWork() = default;
  ~BackgroundWork();  ///< waits for a running job, then ends the thread
  BackgroundWork(const BackgroundWork&) = delete;
  BackgroundWork& operator=(const BackgroundWork&) = delete;

  /// Hands `job` to the thread (waits for a running one first). The job must not throw (it runs
  /// in a noexcept frame). Without a thread to be had, the job runs here, now.
  void start(std::function<void()> job);
  /// Returns when no job runs (at once when none was started). A job still running runs at the
  /// caller's real-time policy meanwhile, if the caller has one (till it finishes).
  void wait();
  /// Whether a job was handed over and has not been waited for.
  [[nodiscard]] bool pending() const { return m_pending; }
  /// Whether a job handed over still runs (wait() would block); never blocks on it.
  [[nodiscard]] bool busy();

 private:
  void serve() noexcept;

  std::thread m_thread;
  std::mutex m_mutex;
  std::condition_variable m_changed;
  std::function<void()> m_job;  // the job to run (empty: none)
  bool m_running = false;       // a job was handed over and has not finished
  bool m_stop = false;
  bool m_pending = false;       // owner's view: started and not waited for
  bool m_lent = false;          // the running job has its waiting owner's real-time policy
};

}  // namespace tissue
