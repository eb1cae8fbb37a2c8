// Real-time discipline through the FMU (STYLE.md principle 6): what the host's haptic thread does every
// 1 ms (device inputs and, when the tissue has a new result, tissue inputs by value reference with the
// importer's thin calls; fmi3DoStep; the outputs read back) allocates nothing after a warm-up, with
// logging off. This executable replaces the global operator new (support/counting_new.hpp).
// HapticLoop.so imports operator new rather than defining it, so the dynamic linker binds its calls to
// this executable's replacement and the FMU's own allocations are counted too; the test checks that by
// provoking one (fmi3GetFMUState builds the state on the heap inside the FMU, and logs nothing).
#include "importer/fmu3.hpp"
#include "importer/fmu3_instance.hpp"
#include "support/counting_new.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <string_view>

namespace tissue::host {
namespace {

constexpr double TICK_S = 1e-3;
constexpr long TISSUE_STEP_TICKS = 33;
constexpr double WALL_STIFFNESS_N_PER_M = 2000.0;

fmi3ValueReference vr(const Fmu3& fmu, std::string_view name) {
  const ModelVariable* variable = fmu.description().find_variable(name);
  if (variable == nullptr) throw std::logic_error("HapticLoop.fmu has no variable " + std::string(name));
  return variable->value_reference;
}

/// The hand: 2 mm into a 2000 N/m wall (4 N: the 3.3 N clamp acts) at 2 Hz, sliding sideways.
std::array<double, 3> hand(long tick) {
  const double t = static_cast<double>(tick) * TICK_S;
  return {0.01 * std::sin(2.0 * std::numbers::pi * 0.7 * t), 0.0, 2e-3 * std::cos(2.0 * std::numbers::pi * 2.0 * t)};
}

TEST(HapticLoopFmuAllocations, TheHapticPathAllocatesNothing) {
  const Fmu3 fmu(HAPTIC_LOOP_FMU_PATH);
  Fmu3Instance instance(fmu, "real-time", false);
  const std::array<fmi3ValueReference, 2> device_vrs{vr(fmu, "device.position"), vr(fmu, "device.orientation")};
  const std::array<fmi3ValueReference, 1> mode_vrs{vr(fmu, "device.toolMode")};
  const std::array<fmi3ValueReference, 7> tissue_vrs{
      vr(fmu, "tissue.time"),         vr(fmu, "tissue.contactPoint"),     vr(fmu, "tissue.contactNormal"),
      vr(fmu, "tissue.contactForce"), vr(fmu, "tissue.contactStiffness"), vr(fmu, "tissue.toolPosition"),
      vr(fmu, "tissue.bladeDepth")};
  const std::array<fmi3ValueReference, 1> active_vrs{vr(fmu, "tissue.contactActive")};
  const std::array<fmi3ValueReference, 4> output_vrs{vr(fmu, "tool.position"), vr(fmu, "tool.orientation"),
                                                     vr(fmu, "device.force"), vr(fmu, "force.cutting")};
  const std::array<fmi3ValueReference, 1> tool_mode_vrs{vr(fmu, "tool.mode")};
  const std::array<fmi3ValueReference, 2> flag_vrs{vr(fmu, "passivity.acted"), vr(fmu, "force.clamped")};
  const std::array<fmi3ValueReference, 1> received_vrs{vr(fmu, "tissue.samplesReceived")};
  ASSERT_EQ(instance.enter_initialization_mode(std::nullopt, 0.0, std::nullopt), fmi3OK);
  ASSERT_EQ(instance.exit_initialization_mode(), fmi3OK);

  // The host's tick; the tissue (a wall whose K_c is half the truth, so the passivity controller acts)
  // reports from the tool position the FMU output, and from 2.5 s the scalpel cuts as deep as it is in.
  std::array<double, 13> outputs{};  // tool.position, tool.orientation, device.force, force.cutting
  int failures = 0, controller_ticks = 0, clamped_ticks = 0, cutting_ticks = 0;
  const auto tick = [&](long k) {
    int bad = 0;
    if (k % TISSUE_STEP_TICKS == 0) {
      const double depth_m = std::max(0.0, -outputs[2]);
      const std::array<double, 23> tissue{static_cast<double>(k) * TICK_S + 1.0,  // a new tissue.time
                                          outputs[0],
                                          outputs[1],
                                          0.0,  // the point under the tool
                                          0.0,
                                          0.0,
                                          1.0,  // normal
                                          0.0,
                                          0.0,
                                          WALL_STIFFNESS_N_PER_M * depth_m,
                                          0.0,
                                          0.0,
                                          0.0,
                                          0.0,
                                          0.0,
                                          0.0,
                                          0.0,
                                          0.0,
                                          0.5 * WALL_STIFFNESS_N_PER_M,
                                          outputs[0],
                                          outputs[1],
                                          outputs[2],  // x0: the tool position
                                          depth_m};
      const std::array<fmi3Boolean, 1> active{depth_m > 0.0};
      bad += instance.set_boolean(active_vrs, active) != fmi3OK;
      bad += instance.set_float64(tissue_vrs, tissue) != fmi3OK;
    }
    const std::array<double, 3> x = hand(k);
    const std::array<double, 7> device{x[0], x[1], x[2], 1.0, 0.0, 0.0, 0.0};
    const std::array<fmi3Int64, 1> mode{k < 2500 ? 1 : 2};
    bad += instance.set_float64(device_vrs, device) != fmi3OK;
    bad += instance.set_int64(mode_vrs, mode) != fmi3OK;
    bad += instance.do_step(static_cast<double>(k) * TICK_S, TICK_S).status != fmi3OK;
    std::array<fmi3Int64, 1> tool_mode{};
    std::array<fmi3Boolean, 2> flags{};
    bad += instance.get_float64(output_vrs, outputs) != fmi3OK;
    bad += instance.get_int64(tool_mode_vrs, tool_mode) != fmi3OK;
    bad += instance.get_boolean(flag_vrs, flags) != fmi3OK;
    failures += bad;
    controller_ticks += flags[0] ? 1 : 0;
    clamped_ticks += flags[1] ? 1 : 0;
    cutting_ticks += outputs[10] != 0.0 || outputs[11] != 0.0 || outputs[12] != 0.0 ? 1 : 0;
  };

  constexpr long WARM_UP = 100, TICKS = 5000;
  for (long k = 0; k < WARM_UP; ++k) tick(k);
  const long before = g_allocations.load();
  for (long k = WARM_UP; k < WARM_UP + TICKS; ++k) tick(k);
  const long allocations = g_allocations.load() - before;
  EXPECT_EQ(allocations, 0) << g_allocated_bytes.load() << " bytes in all";
  EXPECT_EQ(failures, 0);
  // The paths that matter were taken: new samples, contact, the clamp, the controller, cutting.
  std::array<fmi3UInt64, 1> received{};
  ASSERT_EQ(instance.get_uint64(received_vrs, received), fmi3OK);
  EXPECT_GT(received[0], static_cast<fmi3UInt64>(TICKS / TISSUE_STEP_TICKS));
  EXPECT_GT(controller_ticks, 0);
  EXPECT_GT(clamped_ticks, 0);
  EXPECT_GT(cutting_ticks, 0);

  // The counter sees the FMU's allocations.
  const long before_state = g_allocations.load();
  fmi3FMUState state = nullptr;
  ASSERT_EQ(fmu.functions().fmi3GetFMUState(instance.handle(), &state), fmi3OK);
  EXPECT_GT(g_allocations.load() - before_state, 0) << "the FMU's operator new is not this executable's";
  ASSERT_EQ(fmu.functions().fmi3FreeFMUState(instance.handle(), &state), fmi3OK);
}

}  // namespace
}  // namespace tissue::host
