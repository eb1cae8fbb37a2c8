// A JSON string literal of a text (summary.json, compare.json): quotes and backslashes escaped,
// control characters replaced by spaces. The one place the host writes JSON strings (and numbers that
// may not be finite).
#pragma once

#include <cmath>
#include <sstream>
#include <string>

namespace tissue::host {

inline std::string json_string(const std::string& text) {
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      quoted += '\\';
      quoted += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      quoted += ' ';
    } else {
      quoted += c;
    }
  }
  return quoted + "\"";
}

/// A JSON number at 9 significant digits (as the summary writes them), or null for a value JSON
/// cannot hold (NaN, infinity: e.g. a hand that never settled).
inline std::string json_number(double value) {
  if (!std::isfinite(value)) return "null";
  std::ostringstream out;
  out.precision(9);
  out << value;
  return out.str();
}

}  // namespace tissue::host
