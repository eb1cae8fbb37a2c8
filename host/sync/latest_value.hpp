// LatestValue<T>: one writer thread publishes values, one reader thread takes the newest, neither
// ever waits (a triple buffer over one atomic byte). The snapshot exchange of dissertation 5.1.3:
// the dynamics thread publishes the tissue's outputs at the end of each step and takes the tool
// pose at the start of the next; the haptic thread does the reverse every tick. No lock, no
// allocation; each side sees whole values only. T must be copyable.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace tissue::host {

template <class T>
class LatestValue {
 public:
  LatestValue() = default;
  explicit LatestValue(const T& initial) : m_buffers{initial, initial, initial} {}

  /// Every buffer to `value`, nothing fresh. Only before the two threads start.
  void reset(const T& value) {
    m_buffers = {value, value, value};
    m_write = 0;
    m_middle.store(1, std::memory_order_relaxed);
    m_read = 2;
  }

  // --- writer side ---
  /// The buffer to fill; publish() makes it the newest value.
  T& write_buffer() { return m_buffers[m_write]; }
  void publish() {
    const std::uint8_t previous =
        m_middle.exchange(static_cast<std::uint8_t>(m_write | FRESH), std::memory_order_acq_rel);
    m_write = static_cast<std::uint8_t>(previous & INDEX);
  }

  // --- reader side ---
  /// Takes the newest published value if there is one since the last call; true if it did.
  bool update() {
    if ((m_middle.load(std::memory_order_relaxed) & FRESH) == 0) return false;
    const std::uint8_t previous = m_middle.exchange(m_read, std::memory_order_acq_rel);
    m_read = static_cast<std::uint8_t>(previous & INDEX);
    return true;
  }
  /// The value taken by the last update() (or the initial one).
  const T& read_buffer() const { return m_buffers[m_read]; }

 private:
  static constexpr std::uint8_t INDEX = 0x3;
  static constexpr std::uint8_t FRESH = 0x4;
  std::array<T, 3> m_buffers{};
  std::uint8_t m_write = 0;               // writer's own
  std::atomic<std::uint8_t> m_middle{1};  // shared: index | FRESH
  std::uint8_t m_read = 2;                // reader's own
};

}  // namespace tissue::host
