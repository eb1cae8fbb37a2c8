// BackgroundContactStiffness: the effective contact stiffness K_c computed beside the steps (a
// BackgroundWork thread, core/system/background_work.hpp), so that the factorization it costs (the
// frog: ~7 ms, most of a 10 ms step slot) leaves the step's critical path. start() copies the
// matrix and the request in the caller's thread; the worker factorizes the copy and condenses it
// (condense_loaded), touching nothing of the body; take() waits for it and hands the result over.
//
// Determinism: the caller takes the result at a fixed step (Tissue: the next one), never "when
// ready", so a run gives the same K_c with or without the thread (no thread to be had: start()
// computes it in the caller). A finished result can be set from a saved state (restore), so that a
// restored run takes what the original took.
#pragma once

#include "core/contact/contact_stiffness.hpp"
#include "core/system/background_work.hpp"

#include <Eigen/Core>

#include <optional>

namespace tissue {

class BackgroundContactStiffness {
 public:
  enum class State { idle, running, done };

  BackgroundContactStiffness() = default;
  ~BackgroundContactStiffness();  ///< waits for a running worker
  BackgroundContactStiffness(const BackgroundContactStiffness&) = delete;
  BackgroundContactStiffness& operator=(const BackgroundContactStiffness&) = delete;

  /// Copies `system`'s matrix and starts the worker on it (a running one is waited for and dropped
  /// first). A matrix that cannot be copied gives a done, failed result.
  void start(const ShiftedSystem& system, const ContactStiffnessRequest& request);
  /// Starts the worker on K_c of `request` from the factor the last start() made, without loading
  /// or factorizing (condense_factored: forward solves); `request`'s spring fields must be that
  /// factorization's. Call when idle or done; without a factor the result is nothing.
  void start_condense(const ContactStiffnessRequest& request);
  /// Whether the object holds a factor to condense from (the last start() factorized). Call when
  /// not running.
  [[nodiscard]] bool factored() const { return m_effective.rows() > 0; }
  /// Waits for a running worker (running -> done); the result stays to be taken.
  void wait();
  /// Waits, then hands over the result (done -> idle): K_c, or nothing when it could not be condensed
  /// (condense_loaded). Nothing as well when idle.
  std::optional<Eigen::Matrix3d> take();
  /// Waits and drops the result (-> idle).
  void cancel();
  /// A finished result, as if a worker had computed it (a restored state); drops a running one.
  void set_done(const std::optional<Eigen::Matrix3d>& result);

  [[nodiscard]] State state() const { return m_state; }
  /// The finished result (valid in state done, after wait()).
  [[nodiscard]] const std::optional<Eigen::Matrix3d>& result() const { return m_result; }

 private:
  void compute() noexcept;  // the worker's job (or the caller's, without a thread)
  void begin(const ContactStiffnessRequest& request, bool condense_only);  // a job's state, running
  void launch();  // runs compute() on m_work's thread (here, now, without a thread to be had)

  EffectiveContactStiffness m_effective;
  ContactStiffnessRequest m_request;
  std::optional<Eigen::Matrix3d> m_result;
  bool m_condense_only = false;  // the job condenses from the factor held (start_condense)
  State m_state = State::idle;
  BackgroundWork m_work;  // last: its job (compute) uses the members above
};

}  // namespace tissue
