// BackgroundContactStiffness (see background_contact_stiffness.hpp).
#include "core/contact/background_contact_stiffness.hpp"

namespace tissue {

BackgroundContactStiffness::~BackgroundContactStiffness() { m_work.wait(); }

void BackgroundContactStiffness::compute() noexcept {
  try {
    m_result = m_condense_only ? condense_factored(m_effective, m_request) : condense_loaded(m_effective, m_request);
  } catch (...) {  // a request that does not fit, no memory: no K_c (the caller falls back)
    m_result = std::nullopt;
  }
}

void BackgroundContactStiffness::start(const ShiftedSystem& system, const ContactStiffnessRequest& request) {
  begin(request, false);
  try {
    m_effective.load(system);
  } catch (const SolverError&) {  // nothing to factorize: a failed result
    m_state = State::done;
    return;
  }
  launch();
}

void BackgroundContactStiffness::start_condense(const ContactStiffnessRequest& request) {
  begin(request, true);
  launch();
}

void BackgroundContactStiffness::begin(const ContactStiffnessRequest& request, bool condense_only) {
  cancel();
  m_request = request;
  m_result = std::nullopt;
  m_condense_only = condense_only;
  m_state = State::running;
}

void BackgroundContactStiffness::launch() {
  m_work.start([this] { compute(); });  // without a thread to be had, computed here, now
}

void BackgroundContactStiffness::wait() {
  if (m_state != State::running) return;
  m_work.wait();  // the job has run (here, at launch(), when no thread was to be had)
  m_state = State::done;
}

std::optional<Eigen::Matrix3d> BackgroundContactStiffness::take() {
  wait();
  if (m_state != State::done) return std::nullopt;
  m_state = State::idle;
  return m_result;
}

void BackgroundContactStiffness::cancel() {
  wait();
  m_state = State::idle;
  m_result = std::nullopt;
}

void BackgroundContactStiffness::set_done(const std::optional<Eigen::Matrix3d>& result) {
  cancel();
  m_result = result;
  m_state = State::done;
}

}  // namespace tissue
