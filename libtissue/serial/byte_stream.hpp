// Bytes in and out for saved states (FMI's SerializeFMUState): the project's own little-endian
// format, as the x86-64 machines the FMUs are built for. A writer appends fixed-size values,
// length-prefixed strings and byte blocks; a reader checks every length against the bytes left and
// refuses a truncated or malformed buffer with a FormatError, so nothing half-read is ever used.
// Header-only; used by the core's snapshot serializer, the FMI layer and the haptic loop.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace tissue::serial {

/// Bytes that are not what the reader expects (truncated, a bad tag or flag, trailing data).
class FormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteWriter {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
    append(&value, sizeof(T));
  }
  void put_bool(bool value) { put(static_cast<std::uint8_t>(value ? 1 : 0)); }
  void put_string(const std::string& text) {
    put(static_cast<std::uint64_t>(text.size()));
    append(text.data(), text.size());
  }
  void put_bytes(std::span<const std::uint8_t> bytes) {
    put(static_cast<std::uint64_t>(bytes.size()));
    append(bytes.data(), bytes.size());
  }
  [[nodiscard]] const std::vector<std::uint8_t>& bytes() const { return m_bytes; }
  std::vector<std::uint8_t> take() { return std::move(m_bytes); }

 private:
  // resize + memcpy rather than insert: GCC 12 warns falsely (stringop-overflow) on inlined inserts.
  void append(const void* data, std::size_t size) {
    if (size == 0) return;
    const std::size_t at = m_bytes.size();
    m_bytes.resize(at + size);
    std::memcpy(m_bytes.data() + at, data, size);
  }
  std::vector<std::uint8_t> m_bytes;
};

class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : m_bytes(bytes) {}

  template <class T>
  T get() {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
    need(sizeof(T));
    T value;
    std::memcpy(&value, m_bytes.data() + m_offset, sizeof(T));
    m_offset += sizeof(T);
    return value;
  }
  template <class T>
  void get(T& value) {
    value = get<T>();
  }
  bool get_bool() {
    const auto b = get<std::uint8_t>();
    if (b > 1) fail("a flag is neither 0 nor 1");
    return b == 1;
  }
  /// A count of items of at least `item_bytes` each, checked against the bytes left.
  std::size_t count(std::size_t item_bytes) {
    const auto n = get<std::uint64_t>();
    if (item_bytes > 0 && n > (m_bytes.size() - m_offset) / item_bytes) fail("a length exceeds the data");
    return static_cast<std::size_t>(n);
  }
  std::string get_string() {
    const std::size_t n = count(1);
    std::string text(reinterpret_cast<const char*>(m_bytes.data() + m_offset), n);
    m_offset += n;
    return text;
  }
  std::span<const std::uint8_t> get_bytes() {
    const std::size_t n = count(1);
    const std::span<const std::uint8_t> block = m_bytes.subspan(m_offset, n);
    m_offset += n;
    return block;
  }
  void finish() const {
    if (m_offset != m_bytes.size()) fail("trailing bytes after the state");
  }
  [[noreturn]] static void fail(const std::string& what) { throw FormatError("serialized state: " + what); }

 private:
  void need(std::size_t n) const {
    if (n > m_bytes.size() - m_offset) fail("truncated");
  }
  std::span<const std::uint8_t> m_bytes;
  std::size_t m_offset = 0;
};

}  // namespace tissue::serial
