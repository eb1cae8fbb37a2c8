// BackgroundWork (see background_work.hpp).
#include "core/system/background_work.hpp"

#include "core/system/background_policy.hpp"

#include <system_error>
#include <utility>

namespace tissue {

BackgroundWork::~BackgroundWork() {
  if (!m_thread.joinable()) return;
  {
    std::unique_lock lock(m_mutex);
    m_changed.wait(lock, [this] { return !m_running; });
    m_stop = true;
  }
  m_changed.notify_all();
  m_thread.join();
}

void BackgroundWork::start(std::function<void()> job) {
  wait();
  if (!m_thread.joinable()) {
    try {
      m_thread = std::thread([this] { serve(); });
    } catch (const std::system_error&) {
      job();  // no thread to be had: the work is done all the same, here
      return;
    }
  }
  {
    std::lock_guard lock(m_mutex);
    m_job = std::move(job);
    m_running = true;
  }
  m_pending = true;
  m_changed.notify_all();
}

void BackgroundWork::wait() {
  if (!m_pending) return;
  std::unique_lock lock(m_mutex);
  // A job still running gets the waiter's real-time priority until it finishes (the thread takes
  // the normal policy again as it finishes).
  if (m_running && !m_lent) {
    lend_realtime_policy(m_thread.native_handle());
    m_lent = true;
  }
  m_changed.wait(lock, [this] { return !m_running; });
  m_pending = false;
}

bool BackgroundWork::busy() {
  if (!m_pending) return false;
  std::lock_guard lock(m_mutex);  // the job holds it only to take the job and to say it finished
  return m_running;
}

void BackgroundWork::serve() noexcept {
  std::unique_lock lock(m_mutex);
  // The job runs in the time the real-time threads leave idle (unless its owner already waits).
  if (!m_lent) leave_realtime_policy();
  for (;;) {
    m_changed.wait(lock, [this] { return m_stop || static_cast<bool>(m_job); });
    if (m_stop) return;
    std::function<void()> job = std::move(m_job);
    m_job = nullptr;
    lock.unlock();
    job();
    lock.lock();
    if (m_lent) leave_realtime_policy();  // the owner's policy was lent for this job only
    m_lent = false;
    m_running = false;
    m_changed.notify_all();
  }
}

}  // namespace tissue
