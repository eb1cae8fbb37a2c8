// RecycledBytes: copies of a byte string handed to readers in other threads (the recording's frames
// take the surface embedding's bytes to the writer's thread), refilled in a buffer no reader holds
// any more instead of a new one. A new 3 MB buffer (the organ's fine surface after a cut) is fresh
// pages: touching them cost 11-14 ms of a 10 ms tissue slot in a real session (issue 42), against
// 0.1-0.7 ms for the copy into pages already touched.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace tissue::host {

class RecycledBytes {
 public:
  /// A copy of `bytes`, in a buffer of the pool that only the pool holds (its capacity kept), or
  /// in a new one, with room for twice the bytes so that a growing string (more cut faces) is
  /// refilled without allocating. Readers hold the copy as long as they like; the buffer returns to
  /// the pool when the last of them lets go.
  std::shared_ptr<const std::vector<std::uint8_t>> copy(std::span<const std::uint8_t> bytes) {
    for (auto& buffer : m_buffers) {
      if (buffer.use_count() != 1 || buffer->capacity() < bytes.size()) continue;
      // The reader's last access to the buffer happened before its release of it (shared_ptr's
      // release decrement); this fence orders the refill after that access.
      std::atomic_thread_fence(std::memory_order_acquire);
      buffer->assign(bytes.begin(), bytes.end());
      return buffer;
    }
    auto buffer = std::make_shared<std::vector<std::uint8_t>>();
    buffer->reserve(2 * bytes.size());
    buffer->assign(bytes.begin(), bytes.end());
    // A buffer too small for the string stays for smaller ones only while the pool is small.
    if (m_buffers.size() >= MAX_BUFFERS) std::erase_if(m_buffers, [](const auto& b) { return b.use_count() == 1; });
    m_buffers.push_back(buffer);
    return buffer;
  }

  /// Buffers the pool keeps (held by readers or free).
  [[nodiscard]] std::size_t buffer_count() const { return m_buffers.size(); }

 private:
  static constexpr std::size_t MAX_BUFFERS = 16;
  std::vector<std::shared_ptr<std::vector<std::uint8_t>>> m_buffers;
};

}  // namespace tissue::host
