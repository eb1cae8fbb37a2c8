// A probe that slides (issue 42, item 4): swept at constant depth, the frictionless contact's force
// along the sweep is what the surface's slope explains, within 10 % of the normal force. Before the
// contact spring pulled along the normal alone, its isotropic spring held the tissue's material point
// tangentially within each step and dragged the tissue along: 19-35 % of the normal force on a flat
// box at 5-30 mm/s, stick-slip on the organ (point_contact.hpp).
//
// * An inclined plane of tets: a box turned by 20 degrees, the probe pressed 2 mm into its top and
//   swept up the slope parallel to it. A frictionless contact pushes along the plane's normal n, so
//   the horizontal force is f_z n_x / n_z (what the slope explains); the force along the sweep, in the
//   plane, is zero. Asserted at every step of the sweep: |f . t| <= 0.1 |f . n| (t the sweep's unit
//   direction), and the mean horizontal force within 10 % of the slope's share.
// * The frog: swept 2 mm under its back along x at 5 and 30 mm/s; the back's rest slope s along x
//   (over +-3 mm, about a surface edge) explains f_x = -s f_z. Asserted at every step of the sweep:
//   |f_x + s f_z| <= 0.1 |f|. (The frictionless quasi-static poke is not the reference here: its
//   slide by face normals cycles in the probe's pit and does not converge.)
#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include "unit/contact/frog_scene.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>

namespace tissue {
namespace {

using namespace contact_test;

constexpr double DEPTH_M = 2e-3;
constexpr double STEP_S = 0.01;  // the host's tissue slot
constexpr double TOLERANCE = 0.1;

ToolPose probe_at(const Eigen::Vector3d& position_m) {
  return ToolPose{position_m, Eigen::Quaterniond::Identity(), ToolMode::probe};
}

struct Sweep {
  double worst_along_over_normal = 0.0;  // max |f . t| / |f . n| over the sweep
  double least_along_over_normal = 1e300;  // min of the same
  double worst_local = 0.0;                // max |f_t| / f_n about the contact's own normal m
  double least_local = 1e300;              // min of the same
  double mean_local = 0.0;                 // mean of the same
  double mean_horizontal_n = 0.0;        // mean f_x
  double mean_vertical_n = 0.0;          // mean f_z
  bool contact_held = true;
};

// A 12 x 6 x 3 cm box of 5 mm cubes held by its bottom 6 mm, turned by `slope_rad` about y, the probe
// pressed DEPTH_M into its top and swept 4 cm up the slope at `speed_m_per_s`.
// A 12 x 6 x 3 cm box of 5 mm cubes held by its bottom 6 mm, turned by `turn`.
std::unique_ptr<Tissue> box_tissue(const Eigen::Matrix3d& turn, double friction) {
  TetMesh mesh = make_box_mesh(24, 12, 6, 0.005);
  std::vector<int> held;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    Eigen::Vector3d& x = mesh.rest_positions_m[static_cast<size_t>(v)];
    if (x.z() <= 0.006 + 1e-9) held.push_back(v);
    x = turn * x;
  }
  TissueSettings settings;
  settings.body.material = Material{1.0e5, 0.4, 1000.0};
  settings.body.gravity_m_per_s2.setZero();
  settings.body.fixed_vertices = held;
  settings.step_size_s = STEP_S;
  settings.interaction.cutting_enabled = false;
  settings.interaction.contact.friction_coefficient = friction;
  return std::make_unique<Tissue>(mesh, settings);
}

// In the box's own frame: the top at z = 3 cm; 3 cm from the low end, off the vertex lines.
Eigen::Vector3d on_box(const Eigen::Matrix3d& turn, double along_m, double height_m) {
  return turn * Eigen::Vector3d(0.0311 + along_m, 0.0313, 0.03 + height_m);
}

// Presses the probe DEPTH_M into the box's top over 0.3 s and holds it 0.2 s.
void press(Tissue& tissue, const Eigen::Matrix3d& turn) {
  const int press_steps = 30;
  for (int s = 1; s <= 50; ++s) {
    const double height_m = 0.003 - (0.003 + DEPTH_M) * std::min(1.0, static_cast<double>(s) / press_steps);
    tissue.set_tool(probe_at(on_box(turn, 0.0, height_m)));
    tissue.step();
  }
}

// The box turned by `slope_rad` about y, the probe pressed DEPTH_M into its top and swept 4 cm up
// the slope at `speed_m_per_s`.
Sweep sweep_inclined_plane(double slope_rad, double speed_m_per_s, double friction = 0.0) {
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(-slope_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const std::unique_ptr<Tissue> box = box_tissue(turn, friction);
  Tissue& tissue = *box;
  const Eigen::Vector3d normal = turn * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d along = turn * Eigen::Vector3d::UnitX();  // up the slope
  const auto at = [&](double along_m, double height_m) { return on_box(turn, along_m, height_m); };
  press(tissue, turn);
  Sweep sweep;
  const int steps = static_cast<int>(std::lround(0.04 / (speed_m_per_s * STEP_S)));
  int counted = 0;
  for (int s = 1; s <= steps; ++s) {
    tissue.set_tool(probe_at(at(speed_m_per_s * STEP_S * s, -DEPTH_M)));
    tissue.step();
    sweep.contact_held = sweep.contact_held && tissue.contact().active;
    if (s < steps / 8) continue;  // the first millimetres: the tissue starts to move with the probe
    const Eigen::Vector3d force = tissue.contact().force_on_tool_n;
    const double along_over_normal = std::abs(force.dot(along)) / std::abs(force.dot(normal));
    sweep.worst_along_over_normal = std::max(sweep.worst_along_over_normal, along_over_normal);
    sweep.least_along_over_normal = std::min(sweep.least_along_over_normal, along_over_normal);
    const Eigen::Vector3d& m = tissue.contact().normal;
    const double local = (force - force.dot(m) * m).norm() / force.dot(m);
    sweep.worst_local = std::max(sweep.worst_local, local);
    sweep.least_local = std::min(sweep.least_local, local);
    sweep.mean_local += local;
    sweep.mean_horizontal_n += force.x();
    sweep.mean_vertical_n += force.z();
    ++counted;
  }
  sweep.mean_horizontal_n /= counted;
  sweep.mean_vertical_n /= counted;
  sweep.mean_local /= counted;
  return sweep;
}

TEST(SlidingProbe, OnAnInclinedPlaneTheForceIsWhatTheSlopeExplains) {
  const double slope_rad = 20.0 * M_PI / 180.0;
  const Eigen::Vector3d normal = Eigen::AngleAxisd(-slope_rad, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitZ();
  for (const double speed_m_per_s : {0.005, 0.03}) {
    const Sweep sweep = sweep_inclined_plane(slope_rad, speed_m_per_s);
    const double explained_n = sweep.mean_vertical_n * normal.x() / normal.z();
    std::printf("  %2.0f mm/s: worst |f_t| / f_n %.3f; mean f_x %.4f N, the slope explains %.4f N (f_z %.3f N)\n",
                1e3 * speed_m_per_s, sweep.worst_along_over_normal, sweep.mean_horizontal_n, explained_n,
                sweep.mean_vertical_n);
    EXPECT_TRUE(sweep.contact_held);
    EXPECT_LT(sweep.worst_along_over_normal, TOLERANCE);
    EXPECT_NEAR(sweep.mean_horizontal_n, explained_n, TOLERANCE * std::abs(explained_n));
  }
}

// With Coulomb friction mu = 0.3 the same sweep drags: about the contact's own normal m (the dented
// surface's), the force along the surface is mu times the normal force. Asserted: its mean over the
// sweep within 10 % of mu, and every step within 10 % at 5 and 15 mm/s; at 30 mm/s within 13 %: the
// friction force takes the normal force one step late (it is explicit, point_contact.hpp), and over
// the mesh's corrugation the normal force changes by up to ~10 % a step (measured 0.267-0.338 about
// a mean of 0.301). About the undeformed plane the dent's tilt adds a few per cent more. Without the
// friction (mu = 0 in the test above) the same sweeps give at most 0.036.
TEST(SlidingProbe, WithFrictionTheDragIsMuTimesTheNormalForce) {
  const double slope_rad = 20.0 * M_PI / 180.0;
  constexpr double MU = 0.3;
  for (const auto& [speed_m_per_s, tolerance] : {std::pair{0.005, TOLERANCE}, {0.015, TOLERANCE}, {0.03, 0.13}}) {
    const Sweep sweep = sweep_inclined_plane(slope_rad, speed_m_per_s, MU);
    std::printf("  %2.0f mm/s, mu %.1f: |f_t| / f_n from %.3f to %.3f about the plane, %.3f to %.3f (mean %.3f) about m\n",
                1e3 * speed_m_per_s, MU, sweep.least_along_over_normal, sweep.worst_along_over_normal,
                sweep.least_local, sweep.worst_local, sweep.mean_local);
    EXPECT_TRUE(sweep.contact_held);
    EXPECT_NEAR(sweep.mean_local, MU, TOLERANCE * MU);
    EXPECT_LT(sweep.worst_local, (1.0 + tolerance) * MU);
    EXPECT_GT(sweep.least_local, (1.0 - tolerance) * MU);
  }
}

// Static friction: the probe pressed into the flat box, then moved 0.3 mm along it and held. With
// mu = 0.5 the contact sticks and holds the tissue's tangential load, steady (no creep over 0.5 s:
// the last 0.25 s within 2 % of the first); without friction the contact slides back to the normal
// and carries none (below 2 % of the normal force).
TEST(SlidingProbe, WithFrictionAHeldProbeHoldsATangentialLoad) {
  const Eigen::Matrix3d flat = Eigen::Matrix3d::Identity();
  for (const double friction : {0.5, 0.0}) {
    const std::unique_ptr<Tissue> box = box_tissue(flat, friction);
    press(*box, flat);
    Eigen::Vector3d early = Eigen::Vector3d::Zero();
    for (int s = 1; s <= 50; ++s) {
      box->set_tool(probe_at(on_box(flat, 0.0003 * std::min(1.0, s / 3.0), -DEPTH_M)));
      box->step();
      if (s == 25) early = box->contact().force_on_tool_n;
    }
    const Eigen::Vector3d force = box->contact().force_on_tool_n;
    std::printf("  mu %.1f: held 0.3 mm aside, f_x %.4f N (0.25 s before: %.4f N), f_z %.4f N, sticking %d\n", friction,
                force.x(), early.x(), force.z(), box->point_contact().sticking() ? 1 : 0);
    ASSERT_TRUE(box->contact().active);
    if (friction > 0.0) {
      EXPECT_TRUE(box->point_contact().sticking());
      EXPECT_LT(force.x(), -0.05 * force.z());  // the tissue pulls the tool back
      EXPECT_LE(std::abs(force.x()), friction * force.z());
      EXPECT_NEAR(force.x(), early.x(), 0.02 * std::abs(early.x()));
    } else {
      EXPECT_FALSE(box->point_contact().sticking());
      EXPECT_LT(std::abs(force.x()), 0.02 * force.z());
    }
  }
}

// The height of the frog's rest surface above (x, y): the highest upward triangle over the point.
double rest_height_m(const SurfaceMesh& surface, const Eigen::VectorXd& rest, double x_m, double y_m) {
  double height_m = -1.0;
  for (const std::array<int, 3>& t : surface.triangles) {
    if (unit_normal(t, rest).z() <= 0.0) continue;
    const Eigen::Vector3d a = rest.segment<3>(3 * t[0]);
    const Eigen::Vector3d b = rest.segment<3>(3 * t[1]);
    const Eigen::Vector3d c = rest.segment<3>(3 * t[2]);
    // Barycentric coordinates of (x, y) in the triangle's shadow on the xy plane.
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    const double wb = ((x_m - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (y_m - a.y())) / area;
    const double wc = ((b.x() - a.x()) * (y_m - a.y()) - (x_m - a.x()) * (b.y() - a.y())) / area;
    if (wb < 0.0 || wc < 0.0 || wb + wc > 1.0) continue;
    height_m = std::max(height_m, ((1.0 - wb - wc) * a + wb * b + wc * c).z());
  }
  return height_m;
}

TEST(SlidingProbe, OverTheFrogTheForceAlongTheSweepIsWhatTheSlopeExplains) {
  const TetMesh mesh = frog_mesh();
  const SurfaceMesh surface = extract_surface(mesh);
  const Eigen::VectorXd rest = rest_positions(mesh);
  TissueSettings settings;
  settings.body = frog_settings(mesh);
  settings.step_size_s = STEP_S;
  settings.interaction.cutting_enabled = false;
  const double y_m = 0.0013;
  const auto tool_at = [&](double x_m) { return Eigen::Vector3d(x_m, y_m, rest_height_m(surface, rest, x_m, y_m) - DEPTH_M); };
  // The back's slope along x at the tool, over +-SLOPE_BASE_M (about a surface edge: the dent's scale).
  constexpr double SLOPE_BASE_M = 0.003;
  const auto slope_at = [&](double x_m) {
    return (rest_height_m(surface, rest, x_m + SLOPE_BASE_M, y_m) - rest_height_m(surface, rest, x_m - SLOPE_BASE_M, y_m)) /
           (2.0 * SLOPE_BASE_M);
  };
  const double start_x_m = -0.02;
  for (const double speed_m_per_s : {0.005, 0.03}) {
    Tissue tissue(mesh, settings);
    for (int s = 1; s <= 50; ++s) {
      tissue.set_tool(probe_at(tool_at(start_x_m) +
                               Eigen::Vector3d(0.0, 0.0, (0.003 + DEPTH_M) * (1.0 - std::min(1.0, s / 30.0)))));
      tissue.step();
    }
    const int steps = static_cast<int>(std::lround(0.03 / (speed_m_per_s * STEP_S)));  // 3 cm
    double worst = 0.0;
    double worst_x_m = 0.0;
    for (int s = 1; s <= steps; ++s) {
      const double x_m = start_x_m + speed_m_per_s * STEP_S * s;
      tissue.set_tool(probe_at(tool_at(x_m)));
      tissue.step();
      ASSERT_TRUE(tissue.contact().active) << "step " << s;
      if (s < steps / 8) continue;
      const Eigen::Vector3d force = tissue.contact().force_on_tool_n;
      // Along the surface's normal (-s, 0, 1) / |.|: f_x = -s f_z.
      const double error = std::abs(force.x() + slope_at(x_m) * force.z()) / force.norm();
      if (error > worst) {
        worst = error;
        worst_x_m = x_m;
      }
    }
    std::printf("  %2.0f mm/s: worst |f_x + slope f_z| / |f| %.3f (at x %+.1f mm)\n", 1e3 * speed_m_per_s, worst,
                1e3 * worst_x_m);
    EXPECT_LT(worst, TOLERANCE);
  }
}

}  // namespace
}  // namespace tissue
