// Reading back the host's .vtu DataArrays in tests: VTK's "binary" format (base64 of a UInt32 byte
// count and the little-endian values, header_type UInt32) and "ascii", as numbers.
#pragma once

#include <cstdint>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace tissue::host::vtu_read {

inline std::vector<std::uint8_t> decode_base64(std::string_view text) {
  std::vector<std::uint8_t> bytes;
  std::uint32_t bits = 0;
  int count = 0;
  for (const char c : text) {
    int value = -1;
    if (c >= 'A' && c <= 'Z') value = c - 'A';
    else if (c >= 'a' && c <= 'z') value = c - 'a' + 26;
    else if (c >= '0' && c <= '9') value = c - '0' + 52;
    else if (c == '+') value = 62;
    else if (c == '/') value = 63;
    else if (c == '=' || c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    else throw std::invalid_argument(std::string("not base64: '") + c + "'");
    bits = (bits << 6) | static_cast<std::uint32_t>(value);
    count += 6;
    if (count >= 8) {
      count -= 8;
      bytes.push_back(static_cast<std::uint8_t>((bits >> count) & 0xFFU));
    }
  }
  return bytes;
}

template <typename Value>
std::vector<double> unpack(const std::vector<std::uint8_t>& bytes) {
  std::vector<double> values;
  for (std::size_t at = 0; at + sizeof(Value) <= bytes.size(); at += sizeof(Value)) {
    Value value{};
    std::memcpy(&value, bytes.data() + at, sizeof(Value));
    values.push_back(static_cast<double>(value));
  }
  return values;
}

/// The values of a DataArray of `type` (Float64, Int32, Int64, UInt8) whose text is `text` in
/// `format` ("binary": the byte count is checked against the bytes that follow it).
inline std::vector<double> data_array_values(std::string_view type, std::string_view format, std::string_view text) {
  if (format == "ascii") {
    std::istringstream in{std::string(text)};
    std::vector<double> values;
    for (double value = 0.0; in >> value;) values.push_back(value);
    return values;
  }
  if (format != "binary") throw std::invalid_argument("unknown DataArray format " + std::string(format));
  std::vector<std::uint8_t> bytes = decode_base64(text);
  if (bytes.size() < 4) throw std::invalid_argument("a binary DataArray without its byte count");
  std::uint32_t size = 0;
  std::memcpy(&size, bytes.data(), 4);
  bytes.erase(bytes.begin(), bytes.begin() + 4);
  if (size != bytes.size()) {
    throw std::invalid_argument("binary DataArray: header says " + std::to_string(size) + " bytes, " +
                                std::to_string(bytes.size()) + " follow");
  }
  if (type == "Float64") return unpack<double>(bytes);
  if (type == "Int32") return unpack<std::int32_t>(bytes);
  if (type == "Int64") return unpack<std::int64_t>(bytes);
  if (type == "UInt8") return unpack<std::uint8_t>(bytes);
  throw std::invalid_argument("unknown DataArray type " + std::string(type));
}

}  // namespace tissue::host::vtu_read
