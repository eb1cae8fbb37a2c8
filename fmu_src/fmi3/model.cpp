// Model's default output getters: a variable the model has no value of is refused.
#include "fmi3/model.hpp"

namespace tissue::fmi3 {
namespace {

[[noreturn]] void no_value(const VariableInfo& info, const char* type) {
  throw VariableError("no " + std::string(type) + " value for " + std::string(info.name));
}

}  // namespace

void Model::get_float64(const VariableInfo& info, std::span<double>) { no_value(info, "Float64"); }
void Model::get_uint32(const VariableInfo& info, std::span<std::uint32_t>) { no_value(info, "UInt32"); }
void Model::get_uint64(const VariableInfo& info, std::span<std::uint64_t>) { no_value(info, "UInt64"); }
void Model::get_int64(const VariableInfo& info, std::span<std::int64_t>) { no_value(info, "Int64"); }
void Model::get_boolean(const VariableInfo& info, std::span<bool>) { no_value(info, "Boolean"); }

}  // namespace tissue::fmi3
