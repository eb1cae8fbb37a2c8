// A pad contact's state (point_contact.hpp, "A pad"), in the unit suite so that the sanitizer builds
// run it: it ends when the tool is drawn back, and a saved pad contact continues bitwise.
#include "unit/contact/pad_block.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

namespace tissue {
namespace {

using namespace pad_test;

// Found by the palpation scenario: a pad contact that ended (the tool drawn back out of the surface)
// kept its samples, and the next step refused a pad's springs without the point's.
TEST(PadContact, AContactEndsWhenTheToolIsDrawnBack) {
  const std::unique_ptr<Tissue> tissue = block(0.01, 0.012);
  const double x_m = 0.5 * BLOCK_M + 0.0017;
  const double y_m = 0.5 * BLOCK_M + 0.0029;
  pressed_force_n(*tissue, x_m, y_m, PRESS_M);
  ASSERT_FALSE(tissue->contact_spring().pad().empty());
  for (int s = 0; s < 3; ++s) {  // drawn back 5 mm at once, as a hand lets go
    tissue->set_tool(probe_at({x_m, y_m, DEPTH_M + 5e-3}));
    ASSERT_NO_THROW(tissue->step());
  }
  EXPECT_FALSE(tissue->contact().active);
  EXPECT_FALSE(tissue->contact_spring().spring().has_value());
  EXPECT_TRUE(tissue->contact_spring().pad().empty());
}

TEST(PadContact, ASavedPadContactContinuesBitwise) {
  const std::unique_ptr<Tissue> tissue = block(0.01, 0.012);
  const double x_m = 0.5 * BLOCK_M + 0.0017;
  const double y_m = 0.5 * BLOCK_M + 0.0029;
  for (int s = 0; s <= 6; ++s) {
    tissue->set_tool(probe_at({x_m, y_m, DEPTH_M + 1e-3 - 3e-3 * s / 10.0}));
    tissue->step();
  }
  ASSERT_TRUE(tissue->contact().active);
  ASSERT_FALSE(tissue->contact_spring().pad().empty());
  TissueSnapshot snapshot;
  tissue->save(snapshot);
  const auto run_on = [&] {
    std::vector<double> forces;
    for (int s = 7; s <= 12; ++s) {
      tissue->set_tool(probe_at({x_m + 1e-4 * s, y_m, DEPTH_M + 1e-3 - 3e-3 * std::min(s, 10) / 10.0}));
      tissue->step();
      forces.push_back(tissue->contact().force_on_tool_n.z());
    }
    return forces;
  };
  const std::vector<double> continued = run_on();
  tissue->restore(snapshot);
  EXPECT_EQ(run_on(), continued);
}

}  // namespace
}  // namespace tissue
