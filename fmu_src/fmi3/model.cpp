// Model's default output getters: a variable the model has no value of is refused.
#include "fmi3/model.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace tissue::fmi3 {
namespace {

[[noreturn]] void no_value(const VariableInfo& info, const char* type) {
  throw VariableError("no " + std::string(type) + " value for " + std::string(info.name));
}

}  // namespace

long whole_internal_steps(double model_time_s, double current_time_s, double step_s, double internal_step_s) {
  const double h = internal_step_s;
  if (std::abs(current_time_s - model_time_s) > 1e-9 * std::max({1.0, std::abs(model_time_s), h})) {
    throw VariableError("doStep: the communication point " + std::to_string(current_time_s) +
                        " s is not the instance's time " + std::to_string(model_time_s) + " s");
  }
  const double count = std::round(step_s / h);
  if (count < 1.0 || std::abs(count * h - step_s) > 1e-9 * step_s) {
    throw VariableError("doStep: the communication step " + std::to_string(step_s) +
                        " s is not a whole multiple of stepSize " + std::to_string(h) + " s");
  }
  return static_cast<long>(count);
}

void Model::get_float64(const VariableInfo& info, std::span<double>) { no_value(info, "Float64"); }
void Model::get_uint32(const VariableInfo& info, std::span<std::uint32_t>) { no_value(info, "UInt32"); }
void Model::get_uint64(const VariableInfo& info, std::span<std::uint64_t>) { no_value(info, "UInt64"); }
void Model::get_int64(const VariableInfo& info, std::span<std::int64_t>) { no_value(info, "Int64"); }
void Model::get_boolean(const VariableInfo& info, std::span<bool>) { no_value(info, "Boolean"); }
std::span<const std::uint8_t> Model::get_binary(const VariableInfo& info) {
  no_value(info, "Binary");
  return {};
}

}  // namespace tissue::fmi3
