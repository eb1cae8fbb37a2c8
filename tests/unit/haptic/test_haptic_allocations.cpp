// Real-time discipline (STYLE.md principle 6): a haptic tick and a new tissue sample allocate
// nothing, over contact, cutting, the clamp, the rate limiter, the passivity controller, a repaired
// K_c and non-finite device positions. Counts every global operator new in this executable.
#include "haptic/haptic_renderer.hpp"
#include "support/counting_new.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace tissue::haptic {
namespace {

TEST(HapticAllocations, TicksAndSamplesAllocateNothing) {
  HapticRenderer renderer;
  TissueSample sample;
  sample.contact_active = true;
  sample.contact_normal = Eigen::Vector3d::UnitZ();
  sample.tool_position_m = {0.0, 0.0, -1e-3};
  sample.blade_depth_m = 3e-3;
  const double dt_s = 1e-3;
  int controller_ticks = 0;
  int repaired_samples = 0;
  const long before = g_allocations.load();
  for (int k = 0; k < 5000; ++k) {
    const double t = k * dt_s;
    if (k % 33 == 0) {
      sample.force_on_tool_n = {0.0, 0.0, 2.0 + 2.0 * std::sin(t)};  // up to 4 N: the clamp acts
      sample.contact_stiffness_n_per_m = 2000.0 * Eigen::Matrix3d::Identity();
      sample.contact_stiffness_n_per_m(0, 1) = (k / 33) % 2 == 0 ? 0.0 : 3000.0;  // not symmetric: repaired
      renderer.set_sample(sample);
      repaired_samples += renderer.last_sample_repaired() ? 1 : 0;
    }
    Eigen::Vector3d x(0.01 * std::sin(3.0 * t), 0.0, -1e-3 + 1e-3 * std::sin(17.0 * t));
    if (k % 500 == 499) x.x() = std::numeric_limits<double>::quiet_NaN();
    renderer.tick(x, k < 2500 ? ToolMode::probe : ToolMode::scalpel, dt_s);
    controller_ticks += renderer.last_tick().passivity_acted ? 1 : 0;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  // The paths that matter were taken.
  EXPECT_GT(controller_ticks, 0);
  EXPECT_GT(repaired_samples, 0);

  // The counter sees the renderer's allocations: a refused sample builds its message on the heap.
  const long before_refusal = g_allocations.load();
  sample.force_on_tool_n.x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(renderer.set_sample(sample), std::invalid_argument);
  EXPECT_GT(g_allocations.load() - before_refusal, 0);
}

}  // namespace
}  // namespace tissue::haptic
