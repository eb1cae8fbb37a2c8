// pose_message.cpp - see pose_message.hpp.
#include "view/pose_message.hpp"

#include <nlohmann/json.hpp>

#include <cmath>
#include <optional>

namespace tissue::host {
namespace {

std::optional<PoseMessage> refuse(std::string* why, const char* reason) {
  if (why != nullptr) *why = reason;
  return std::nullopt;
}

// A JSON array of exactly N finite numbers.
template <std::size_t N>
bool read_numbers(const nlohmann::json& value, std::array<double, N>& out) {
  if (!value.is_array() || value.size() != N) return false;
  for (std::size_t k = 0; k < N; ++k) {
    if (!value[k].is_number()) return false;
    out[k] = value[k].get<double>();
    if (!std::isfinite(out[k])) return false;
  }
  return true;
}

}  // namespace

std::optional<PoseMessage> parse_pose_message(std::string_view text, std::string* why) {
  if (text.size() > MAX_VIEW_MESSAGE_BYTES) return refuse(why, "longer than 512 bytes");
  const nlohmann::json message = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (message.is_discarded()) return refuse(why, "not JSON");
  if (!message.is_object()) return refuse(why, "not a JSON object");
  const auto type = message.find("type");
  if (type == message.end() || !type->is_string() || type->get<std::string>() != "pose") {
    return refuse(why, "not a pose message");
  }
  PoseMessage result;
  const auto seq = message.find("seq");
  if (seq == message.end() || !seq->is_number_unsigned()) return refuse(why, "seq is not a non-negative integer");
  result.seq = seq->get<std::uint64_t>();
  const auto position = message.find("position_m");
  if (position == message.end() || !read_numbers(*position, result.pose.position_m)) {
    return refuse(why, "position_m is not 3 finite numbers");
  }
  const auto orientation = message.find("orientation_wxyz");
  std::array<double, 4> q{};
  if (orientation == message.end() || !read_numbers(*orientation, q)) {
    return refuse(why, "orientation_wxyz is not 4 finite numbers");
  }
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(norm > 1e-9) || !std::isfinite(norm)) return refuse(why, "orientation_wxyz is (nearly) zero");
  for (std::size_t k = 0; k < 4; ++k) result.pose.orientation_wxyz[k] = q[k] / norm;
  const auto mode = message.find("mode");
  if (mode == message.end() || !mode->is_string()) return refuse(why, "mode is not a string");
  const std::string name = mode->get<std::string>();
  const std::optional<ToolMode> named = tool_mode_named(name);
  if (!named) return refuse(why, "mode is not none, probe or scalpel");
  result.pose.mode = *named;
  return result;
}

}  // namespace tissue::host
