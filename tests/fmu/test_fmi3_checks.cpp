// Where the FMI layer checks a set value (issue 19): a set of inputs alone runs no model check (the
// model checks inputs once per step, where it uses them), a set that includes a parameter runs the
// model's parameter checks once, and the schema's own rules (here an orientation's min_norm) refuse
// a value at the set and in a deserialized state, with nothing changed. A model that counts its
// checks stands in for the FMUs' (this executable defines the layer's two entry points).
#include "fmi3/instance.hpp"
#include "fmi3/model.hpp"
#include "fmi3/variable_table.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace tissue::fmi3 {
namespace {

enum class Vr : ValueReference { time = 0, gain = 1, position = 2, orientation = 3 };

constexpr std::array<VariableInfo, 4> VARIABLES{
    independent_time(Vr::time),
    parameter(Vr::gain, "gain", VariableType::float64).start("1").describe("A parameter the model checks (>= 0)"),
    input(Vr::position, "position", VariableType::float64, Variability::continuous)
        .unit("m")
        .start("0 0 0")
        .shape(fixed_size(3))
        .describe("An input with no rule beyond finiteness"),
    input(Vr::orientation, "orientation", VariableType::float64, Variability::continuous)
        .start("1 0 0 0")
        .shape(fixed_size(4))
        .min_norm(1e-12)
        .describe("A quaternion the model normalizes where it uses it"),
};

const ModelDescription DESCRIPTION{"Counting", "{counting}", VARIABLES, {}, "A model that counts its checks", {}, {}};

int g_parameter_checks = 0;

class CountingModel final : public Model {
 public:
  void validate_parameters(const ValueStore& values) const override {
    ++g_parameter_checks;
    if (values.float64(static_cast<ValueReference>(Vr::gain)) < 0.0) throw VariableError("gain must be >= 0");
  }
  void enter_initialization_mode(double /*start_time_s*/) override {}
  void exit_initialization_mode() override {}
  StepOutcome do_step(double current_time_s, double step_s) override { return {true, current_time_s + step_s}; }
  void reset() override {}
  std::unique_ptr<ModelState> save() const override { return std::make_unique<ModelState>(); }
  void restore(const ModelState& /*state*/) override {}
  void serialize(const ModelState& /*state*/, serial::ByteWriter& /*writer*/) const override {}
  std::unique_ptr<ModelState> deserialize(serial::ByteReader& /*reader*/) const override {
    return std::make_unique<ModelState>();
  }
};

void set(Instance& instance, std::vector<ValueReference> vrs, std::vector<double> values) {
  instance.set<double>(vrs, values);
}
constexpr auto vr(Vr v) { return static_cast<ValueReference>(v); }

TEST(Fmi3Checks, InputSetsRunNoModelCheckAndParameterSetsOne) {
  g_parameter_checks = 0;
  Instance instance(DESCRIPTION, "counting", "", false, {});
  EXPECT_EQ(g_parameter_checks, 1) << "the start values are checked once, at instantiation";
  for (int n = 0; n < 1000; ++n) {
    set(instance, {vr(Vr::position)}, {0.001 * n, 0.0, 0.0});
    set(instance, {vr(Vr::orientation)}, {1.0, 0.0, 0.0, 0.001 * n});
  }
  EXPECT_EQ(g_parameter_checks, 1) << "2000 input sets";
  set(instance, {vr(Vr::gain)}, {2.0});
  EXPECT_EQ(g_parameter_checks, 2);
  set(instance, {vr(Vr::gain), vr(Vr::position)}, {3.0, 1.0, 2.0, 3.0});
  EXPECT_EQ(g_parameter_checks, 3) << "a parameter and an input in one call: one check";
  EXPECT_THROW(set(instance, {vr(Vr::position), vr(Vr::gain)}, {4.0, 5.0, 6.0, -1.0}), VariableError);
  EXPECT_EQ(instance.values().float64(vr(Vr::gain)), 3.0) << "a refused set changes nothing";
  EXPECT_EQ(instance.values().float64_array(vr(Vr::position))[0], 1.0);
}

TEST(Fmi3Checks, AnOrientationWithNoNormIsRefusedAtTheSetAndInAState) {
  Instance instance(DESCRIPTION, "counting", "", false, {});
  EXPECT_THROW(set(instance, {vr(Vr::orientation)}, {0.0, 0.0, 0.0, 0.0}), VariableError);
  EXPECT_THROW(set(instance, {vr(Vr::orientation)}, {1e-13, 0.0, 0.0, 0.0}), VariableError);
  EXPECT_EQ(instance.values().float64_array(vr(Vr::orientation))[0], 1.0) << "nothing changed";
  set(instance, {vr(Vr::orientation)}, {0.0, 0.0, 0.0, 1e-11});  // small, but a direction

  // A serialized state whose orientation has no norm (its four doubles zeroed) is refused.
  set(instance, {vr(Vr::orientation)}, {0.5, 0.5, 0.5, 0.5});
  instance.enter_initialization_mode(0.0);
  instance.exit_initialization_mode();
  std::vector<std::uint8_t> bytes = instance.serialize(*instance.save());
  ASSERT_NO_THROW((void)instance.deserialize(bytes));
  const std::array<double, 4> quaternion{0.5, 0.5, 0.5, 0.5};
  std::array<std::uint8_t, sizeof quaternion> pattern{};
  std::memcpy(pattern.data(), quaternion.data(), sizeof quaternion);
  const auto at = std::search(bytes.begin(), bytes.end(), pattern.begin(), pattern.end());
  ASSERT_NE(at, bytes.end());
  std::fill(at, at + static_cast<std::ptrdiff_t>(pattern.size()), std::uint8_t{0});
  EXPECT_THROW((void)instance.deserialize(bytes), VariableError);
}

}  // namespace

const ModelDescription& model_description() { return DESCRIPTION; }
std::unique_ptr<Model> make_model(const ModelContext& /*context*/, const ValueStore& /*values*/) {
  return std::make_unique<CountingModel>();
}

}  // namespace tissue::fmi3
