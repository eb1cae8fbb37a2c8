// A probe with a pad (issue 42, items 2 and 3; point_contact.hpp, "A pad"). Under a point the
// force follows the mesh, not the tissue: a point load has no continuum limit (the displacement
// under it is unbounded), and on a mesh of edge h the stiffness under a point is ~ E h, changing
// with h and with where the point lands among the vertices. Under a flat pad of radius a the force
// has a limit (Boussinesq's punch, ~ 2 a E d / (1 - nu^2) on a half-space), approached once h < a.
//
// * A 6 x 6 x 3 cm block held by its base (E 100 kPa, nu 0.45), pressed 2 mm at the top's centre at
//   four landing points off the grid, quasi-statically (exact solves, heavy damping, 40 long steps),
//   on 10 and 6 mm grids. Over the landings a point's force spreads by 62 %, a 12 mm pad's by 11-13 %;
//   from the 10 to the 6 mm grid a point's mean force falls as h does (x 1.93; h: x 1.67), the pad's
//   by x 1.33, what the coarse grid's stiffer tets leave (linear tets at nu 0.45). Asserted: the pad's
//   spread under a third of the point's, and its change with h under half of the point's excess.
// * K_c: the pad's contact stiffness (the condensation through its springs, the Woodbury form of
//   pad_stiffness_n_per_m) against the slope of the held force between two depths of the full
//   nonlinear model at 0.2 and 0.25 mm, within 2 % (0.6 % measured).
// * A pad with friction, or with the point's elementLocal K_c, is refused; the force is continuous
//   when the pad is drawn back a little. (A pad contact's end and its saved state:
//   tests/unit/contact/test_pad_contact.cpp, which the sanitizer builds run too.)
#include "core/parameter_error.hpp"
#include "unit/contact/pad_block.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace tissue {
namespace {

using namespace pad_test;

struct Landings {
  double mean_n = 0.0;
  double spread = 0.0;  // (max - min) / mean
};

Landings press_at_landings(double edge_m, double pad_radius_m) {
  // Off the grid's vertex lines, in units of the edge from the top's centre.
  const std::array<Eigen::Vector2d, 4> offsets{Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(0.5, 0.5),
                                               Eigen::Vector2d(0.33, 0.67), Eigen::Vector2d(0.9, 0.45)};
  std::vector<double> forces;
  for (const Eigen::Vector2d& offset : offsets) {
    const std::unique_ptr<Tissue> tissue = block(edge_m, pad_radius_m);
    forces.push_back(
        pressed_force_n(*tissue, 0.5 * BLOCK_M + offset.x() * edge_m, 0.5 * BLOCK_M + offset.y() * edge_m, PRESS_M));
  }
  Landings out;
  for (const double f : forces) out.mean_n += f / static_cast<double>(forces.size());
  const auto [least, most] = std::minmax_element(forces.begin(), forces.end());
  out.spread = (*most - *least) / out.mean_n;
  return out;
}

TEST(PadProbe, ItsForceFollowsTheTissueWhereAPointsFollowsTheMesh) {
  constexpr double PAD_M = 0.012;
  const Landings point_coarse = press_at_landings(0.01, 0.0);
  const Landings point_fine = press_at_landings(0.006, 0.0);
  const Landings pad_coarse = press_at_landings(0.01, PAD_M);
  const Landings pad_fine = press_at_landings(0.006, PAD_M);
  std::printf(
      "point: %.3f N (spread %.1f%%) on 10 mm, %.3f N (%.1f%%) on 6 mm; pad: %.3f N (%.1f%%), %.3f N (%.1f%%)\n",
      point_coarse.mean_n, 100 * point_coarse.spread, point_fine.mean_n, 100 * point_fine.spread, pad_coarse.mean_n,
      100 * pad_coarse.spread, pad_fine.mean_n, 100 * pad_fine.spread);
  for (const Landings& l : {point_coarse, point_fine, pad_coarse, pad_fine}) EXPECT_GT(l.mean_n, 0.0);
  EXPECT_LT(pad_coarse.spread, point_coarse.spread / 3.0);
  EXPECT_LT(pad_fine.spread, point_fine.spread / 3.0);
  const double point_change = point_coarse.mean_n / point_fine.mean_n;
  const double pad_change = pad_coarse.mean_n / pad_fine.mean_n;
  EXPECT_GT(point_change, 1.5);  // ~ the edges' ratio, 1.67: no limit
  EXPECT_LT(pad_change - 1.0, 0.5 * (point_change - 1.0));
}

TEST(PadProbe, ContactStiffnessIsTheSlopeOfTheHeldForce) {
  constexpr double PAD_M = 0.008;
  constexpr double SHALLOW_M = 0.2e-3;  // shallow: the co-rotational tangent omits dR/du, 3 % by 1 mm under an 8 mm pad
  constexpr double DEEPER_M = 0.25e-3;
  const double x_m = 0.5 * BLOCK_M + 0.0013;
  const double y_m = 0.5 * BLOCK_M + 0.0021;
  const std::unique_ptr<Tissue> shallow = block(0.006, PAD_M);
  const double f_shallow_n = pressed_force_n(*shallow, x_m, y_m, SHALLOW_M);
  const double k_shallow = shallow->contact().stiffness_n_per_m(2, 2);
  const std::unique_ptr<Tissue> deeper = block(0.006, PAD_M);
  const double f_deeper_n = pressed_force_n(*deeper, x_m, y_m, DEEPER_M);
  const double k_deeper = deeper->contact().stiffness_n_per_m(2, 2);
  const double slope_n_per_m = (f_deeper_n - f_shallow_n) / (DEEPER_M - SHALLOW_M);
  const double condensed_n_per_m = 0.5 * (k_shallow + k_deeper);
  std::printf("held forces %.5f / %.5f N: slope %.1f N/m; K_c %.1f / %.1f N/m\n", f_shallow_n, f_deeper_n,
              slope_n_per_m, k_shallow, k_deeper);
  EXPECT_NEAR(condensed_n_per_m, slope_n_per_m, 0.02 * slope_n_per_m);
  // The pad's K_c acts along its normal alone (it slides).
  const Eigen::Matrix3d k = deeper->contact().stiffness_n_per_m;
  EXPECT_NEAR(k(0, 0), 0.0, 1e-9 * k(2, 2));
  EXPECT_NEAR(k(1, 1), 0.0, 1e-9 * k(2, 2));
}

TEST(PadProbe, AFrictionalOrElementLocalPadIsRefused) {
  const TetMesh mesh = make_box_mesh(4, 4, 2, 0.01);
  TissueSettings settings = block_settings(0.005);
  settings.body.fixed_vertices = {0, 1, 2};
  settings.interaction.contact.friction_coefficient = 0.3;
  EXPECT_THROW(Tissue(mesh, settings), ParameterError);
  settings.interaction.contact.friction_coefficient = 0.0;
  settings.interaction.contact.stiffness_model = ContactStiffnessModel::element_local;
  EXPECT_THROW(Tissue(mesh, settings), ParameterError);
  settings.interaction.contact.stiffness_model = ContactStiffnessModel::effective_static;
  settings.interaction.contact.pad_radius_m = -0.001;
  EXPECT_THROW(Tissue(mesh, settings), ParameterError);
}

// Found by the palpation scenario's hand: a pad drawn back by a few tens of microns left every sample
// short of its plane, and the force fell to the centre sample's share for a step (the hand rang at
// 50 Hz between 1 and 9 N). The samples follow as the contact does: drawn back by less than the
// pressed surface's rebound, the force falls by K_c times the retreat, not by most of itself.
TEST(PadProbe, TheForceIsContinuousWhenThePadIsDrawnBackALittle) {
  const std::unique_ptr<Tissue> tissue = block(0.006, 0.012);
  const double x_m = 0.5 * BLOCK_M + 0.0013;
  const double y_m = 0.5 * BLOCK_M + 0.0021;
  const double held_n = pressed_force_n(*tissue, x_m, y_m, PRESS_M);
  const double stiffness_n_per_m = tissue->contact().stiffness_n_per_m(2, 2);
  constexpr double RETREAT_M = 50e-6;
  tissue->set_tool(probe_at({x_m, y_m, DEPTH_M - PRESS_M + RETREAT_M}));
  tissue->step();
  const double expected_n = held_n - stiffness_n_per_m * RETREAT_M;
  std::printf("held %.4f N, drawn back 50 um: %.4f N (K_c predicts %.4f N)\n", held_n,
              tissue->contact().force_on_tool_n.z(), expected_n);
  // 0.5 %: the linear model's error over 50 um is second order (the held force's curvature, ~1e-5 of
  // it); without the samples following, the force fell 2 % below it within this damped 50 ms step.
  EXPECT_NEAR(tissue->contact().force_on_tool_n.z(), expected_n, 0.005 * held_n);
}

}  // namespace
}  // namespace tissue
