// A JSON string literal of a text (summary.json, compare.json): quotes and backslashes escaped,
// control characters replaced by spaces. The one place the host writes JSON strings.
#pragma once

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

}  // namespace tissue::host
