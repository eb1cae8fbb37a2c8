// FramePipe: surface frames handed from the dynamics thread to a writer thread over a fixed pool,
// so that capturing a frame allocates nothing in the loop: the dynamics thread takes a free frame,
// fills it and pushes it; the writer waits for filled frames, writes them and gives them back. A
// full pool drops the frame (the caller counts it) instead of waiting.
#pragma once

#include "output/surface_frame.hpp"

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>

namespace tissue::host {

class FramePipe {
 public:
  explicit FramePipe(std::size_t pool) {
    for (std::size_t k = 0; k < pool; ++k) m_free.push_back(std::make_unique<SurfaceFrame>());
  }
  /// Sizes every frame's arrays once, before the run, so that capturing allocates nothing.
  template <class Prepare>
  void prepare(Prepare&& prepare_frame) {
    for (auto& frame : m_free) prepare_frame(*frame);
  }
  std::unique_ptr<SurfaceFrame> take_free() {
    const std::lock_guard lock(m_mutex);
    if (m_free.empty()) return nullptr;
    auto frame = std::move(m_free.back());
    m_free.pop_back();
    return frame;
  }
  void push_filled(std::unique_ptr<SurfaceFrame> frame) {
    {
      const std::lock_guard lock(m_mutex);
      m_filled.push_back(std::move(frame));
    }
    m_ready.notify_one();
  }
  std::unique_ptr<SurfaceFrame> wait_filled(std::chrono::milliseconds timeout) {
    std::unique_lock lock(m_mutex);
    m_ready.wait_for(lock, timeout, [&] { return !m_filled.empty(); });
    if (m_filled.empty()) return nullptr;
    auto frame = std::move(m_filled.front());
    m_filled.pop_front();
    return frame;
  }
  void give_back(std::unique_ptr<SurfaceFrame> frame) {
    const std::lock_guard lock(m_mutex);
    m_free.push_back(std::move(frame));
  }

 private:
  std::mutex m_mutex;
  std::condition_variable m_ready;
  std::vector<std::unique_ptr<SurfaceFrame>> m_free;
  std::deque<std::unique_ptr<SurfaceFrame>> m_filled;
};

}  // namespace tissue::host
