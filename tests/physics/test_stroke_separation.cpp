// Every stroke through the body cuts it free (issue 41): a vertical scalpel drawn once across the
// whole width of a held, sagging body, then taken away, with exact solves (CHOLMOD, so that the
// solver is not the cause) and no damping. Judged by physics: the far side is a free piece, its
// lumped mass is rho times its volume and its load its weight (to 1e-12), and it falls at g (its
// centre of mass's acceleration and its momentum, to 1e-6: the law is exact for a free piece under
// backward Euler). The matrix spans the speed (1 cm/s to 1 m/s), the body (the frog, beams of 5 mm
// and 1 cm cubes) and where the blade's plane falls between vertex layers (on a layer, 0.1%, 6% and
// 50% of an edge past one). Before vertex sides, edges decided at different moments disagreed
// where the sagging body carried vertices near the plane across it and back while the blade
// passed: the tets between stayed uncut and held the far side (9 of 24 strokes came free).
#include "core/fixed_region.hpp"
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "core/tissue.hpp"
#include "core/mesh/topology.hpp"
#include "support/under_sanitizer.hpp"
#include "unit/fem/body_pieces.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace tissue {
namespace {

using xfem_test::BodyPiece;

constexpr double GRAVITY = 9.81;
constexpr double DENSITY = 1000.0;
constexpr double FALL_TOLERANCE = 1e-6;

enum class Body { frog, beam_5mm, beam_1cm, organ, organ_coarse };

struct Case {
  Body body;
  double plane;  // frog: fraction of its length; beams: vertex layer + fraction of an edge past it
  double speed_m_per_s;
  double step_s;
  std::string name;
  double young_modulus_pa = 3.0e5;
};

TetMesh mesh_of(Body body) {
  switch (body) {
    case Body::frog: return read_mesh(std::string(TISSUE_MESH_DIR) + "/frog.veg");
    case Body::beam_5mm: return make_box_mesh(20, 4, 4, 0.005);
    case Body::beam_1cm: return make_box_mesh(10, 2, 2, 0.01);
    case Body::organ: return read_mesh(std::string(TISSUE_MESH_DIR) + "/liver.veg");
    case Body::organ_coarse: return read_mesh(std::string(TISSUE_MESH_DIR) + "/liver_coarse.veg");
  }
  return {};
}

// The beams' planes and clamp are in vertex layers; the frog's and the organ's in fractions of the length.
bool is_beam(Body body) { return body == Body::beam_5mm || body == Body::beam_1cm; }

struct Box {
  Eigen::Vector3d low, high;
};

Box rest_box(const TetMesh& mesh) {
  Box box{mesh.rest_positions_m.front(), mesh.rest_positions_m.front()};
  for (const Eigen::Vector3d& p : mesh.rest_positions_m) {
    box.low = box.low.cwiseMin(p);
    box.high = box.high.cwiseMax(p);
  }
  return box;
}

// The blade's plane x = plane_x_m of a case.
double plane_x_m(const Case& c, const Box& box) {
  if (!is_beam(c.body)) return box.low.x() + c.plane * (box.high.x() - box.low.x());
  const double edge_m = c.body == Body::beam_5mm ? 0.005 : 0.01;
  return c.plane * edge_m;  // the beams start at x = 0
}

// Rest volume of the tets whose centroid lies beyond x where the body is (`positions_m`, 3 per
// vertex): the far side, to within a layer of tets.
double volume_beyond_m3(const TetMesh& mesh, const Eigen::VectorXd& positions_m, double x_m) {
  double volume = 0.0;
  for (const Tet& tet : mesh.tets) {
    const std::array<Eigen::Vector3d, 4> p = {mesh.rest_positions_m[static_cast<size_t>(tet[0])],
                                              mesh.rest_positions_m[static_cast<size_t>(tet[1])],
                                              mesh.rest_positions_m[static_cast<size_t>(tet[2])],
                                              mesh.rest_positions_m[static_cast<size_t>(tet[3])]};
    double centroid_x_m = 0.0;
    for (const int v : tet) centroid_x_m += 0.25 * positions_m(3 * v);
    if (centroid_x_m <= x_m) continue;
    volume += std::abs((p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0])) / 6.0;
  }
  return volume;
}

class StrokeSeparation : public ::testing::TestWithParam<Case> {};

TEST_P(StrokeSeparation, TheFarSideFallsFreeAtG) {
  const Case& c = GetParam();
  const TetMesh mesh = mesh_of(c.body);
  const Box box = rest_box(mesh);
  TissueSettings settings;
  settings.body.material = Material{c.young_modulus_pa, 0.4, DENSITY};
  settings.body.damping = RayleighDamping{0.0, 0.0};
  settings.body.gravity_m_per_s2 = Eigen::Vector3d(0.0, 0.0, -GRAVITY);
  const double held_m = !is_beam(c.body) ? 0.3 * (box.high.x() - box.low.x()) : 1e-6;
  settings.body.fixed_vertices = vertices_at_minimum(mesh, 0, held_m / (box.high.x() - box.low.x()));
  settings.solver.kind = LinearSolverKind::cholmod;
  settings.step_size_s = c.step_s;
  settings.interaction.blade_length_m = 0.15;
  // Reaching 5 cm below the body at rest; a soft body (30 kPa) falls further while the blade passes:
  // then from 30 cm below it.
  const double below_m = c.young_modulus_pa < 1e5 ? 0.3 : 0.05;
  settings.interaction.blade_length_m = std::max(0.15, box.high.z() - box.low.z() + below_m + 0.1);
  Tissue tissue(mesh, settings);
  const double x = plane_x_m(c, box);
  const double y_from = box.low.y() - 0.01;
  const double y_to = box.high.y() + 0.01;
  const double z = box.low.z() - below_m;
  // Released from rest: the body sags and swings while the blade passes. The scalpel is brought to
  // the stroke's start meanwhile (at most tool.maxSpeed).
  tissue.set_tool(ToolPose{Eigen::Vector3d(x, y_from, z), Eigen::Quaterniond::Identity(), ToolMode::none});
  for (int n = 0; n < static_cast<int>(std::lround(0.1 / c.step_s)); ++n) tissue.step();
  const Eigen::VectorXd at_stroke_m = tissue.current_positions_m();
  const int steps = static_cast<int>(std::ceil((y_to - y_from) / (c.speed_m_per_s * c.step_s)));
  for (int n = 0; n <= steps; ++n) {
    const double y = y_from + (y_to - y_from) * n / steps;
    tissue.set_tool(ToolPose{Eigen::Vector3d(x, y, z), Eigen::Quaterniond::Identity(), ToolMode::scalpel});
    tissue.step();
  }
  tissue.set_tool(ToolPose{Eigen::Vector3d(x, y_to + 0.2, z), Eigen::Quaterniond::Identity(), ToolMode::none});
  tissue.step();

  std::vector<BodyPiece> free;
  for (const BodyPiece& piece : xfem_test::body_pieces(tissue.body())) {
    if (!piece.held) free.push_back(piece);
  }
  const double far_m3 = volume_beyond_m3(mesh, at_stroke_m, x);
  double chips_m3 = 0.0;
  for (std::size_t k = 1; k < free.size(); ++k) chips_m3 += free[k].volume_m3;
  std::printf("%s: %d sessions, %d cut tets, %zu free pieces, the largest %.3g of the far side's volume, the others %.3g\n",
              c.name.c_str(), tissue.cutter().cut_id() + 1, tissue.body().cut_tet_count(), free.size(),
              free.empty() ? 0.0 : free[0].volume_m3 / far_m3, chips_m3 / far_m3);
  ASSERT_FALSE(free.empty()) << "the stroke did not cut the far side free";
  // One free piece: no chips (a piece swinging on its last bridge into the blade shed specks while
  // the vertices it carried back into the blade's path were decided there).
  EXPECT_EQ(free.size(), 1u) << "chips of " << chips_m3 / far_m3 << " of the far side";
  // The sagged body is cut along a plane of the deformed configuration: the far side's rest volume
  // (where the body was when the stroke began) to within the tets cut (the layer the plane crosses;
  // a wider band where it crosses a body bent or swinging while the blade passes).
  double band_m3 = 0.0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    if (tissue.body().cut_tet_index(t) >= 0) band_m3 += tissue.body().elasticity().rest(t).volume_m3;
  }
  EXPECT_NEAR(free[0].volume_m3, far_m3, band_m3);

  const DeformableBody& body = tissue.body();
  const BodyPiece& piece = free[0];
  const Eigen::VectorXd c_z = xfem_test::translation(body, piece, 2);
  EXPECT_NEAR(c_z.dot(body.mass_kg()), piece.mass_kg, 1e-12 * piece.mass_kg) << "lumped mass = rho V";
  EXPECT_NEAR(c_z.dot(body.external_force_n()), -piece.mass_kg * GRAVITY, 1e-12 * piece.mass_kg * GRAVITY);

  // Backward Euler's free fall: P_{n+1} = P_n - h m g, and the centre of mass accelerates at g.
  const auto momentum_z = [&] { return c_z.dot(body.mass_kg().cwiseProduct(tissue.state().velocity_m_per_s)); };
  double momentum_law = momentum_z();
  std::vector<Eigen::Vector3d> centres;
  double worst_acceleration = 0.0;
  double worst_momentum = 0.0;
  for (int n = 0; n < static_cast<int>(std::lround(0.2 / c.step_s)); ++n) {
    centres.push_back(xfem_test::mean_displacement_m(body, piece, tissue.state().displacement_m));
    tissue.step();
    momentum_law -= c.step_s * piece.mass_kg * GRAVITY;
    worst_momentum = std::max(worst_momentum, std::abs(momentum_z() - momentum_law) / std::abs(momentum_law));
    if (centres.size() < 2) continue;
    const Eigen::Vector3d now = xfem_test::mean_displacement_m(body, piece, tissue.state().displacement_m);
    const Eigen::Vector3d a = (now - 2.0 * centres.back() + centres[centres.size() - 2]) / (c.step_s * c.step_s);
    worst_acceleration = std::max(worst_acceleration, (a - Eigen::Vector3d(0.0, 0.0, -GRAVITY)).norm() / GRAVITY);
  }
  EXPECT_LT(worst_acceleration, FALL_TOLERANCE);
  EXPECT_LT(worst_momentum, FALL_TOLERANCE);
}

std::vector<Case> cases() {
  std::vector<Case> all;
  const auto add = [&](Body body, const char* body_name, double plane, const char* plane_name, double speed,
                       const char* speed_name, double step_s, double young_modulus_pa = 3.0e5, const char* stiffness = "") {
    // Under a sanitizer the strokes at a hand's slowest speeds (hundreds of exact steps) are left to
    // the release suite.
    if (test::UNDER_SANITIZER && speed < 0.1) return;
    all.push_back(Case{body, plane, speed, step_s,
                       std::string(body_name) + stiffness + "_" + plane_name + "_" + speed_name, young_modulus_pa});
  };
  // The sag: softer and stiffer than the 300 kPa of the rest. At 30 kPa the 10 cm beam held at one
  // end swings down and back through x = 5 cm (its far end then reaches only x = 3.6 cm) while the
  // blade passes: it is cut 2 cm from the clamp.
  for (const auto& [young_modulus_pa, stiffness] : {std::pair{3.0e4, "30kPa"}, std::pair{1.0e6, "1MPa"}}) {
    add(Body::frog, "Frog", 0.55, "at55", 0.2, "20cmps", 0.01, young_modulus_pa, stiffness);
  }
  add(Body::beam_5mm, "Beam5mm", 4.001, "past0p1pctAt2cm", 0.2, "20cmps", 0.01, 3.0e4, "30kPa");
  add(Body::beam_5mm, "Beam5mm", 10.001, "past0p1pct", 0.2, "20cmps", 0.01, 1.0e6, "1MPa");
  // The organ's physics mesh of the real-time scenes (meshes/liver_coarse.veg, 6.1k tets graded by
  // curvature; issue 42): across the thick middle and through the thin left lobe, as cut_organ.
  add(Body::organ_coarse, "OrganCoarse", 0.55, "at55", 0.2, "20cmps", 0.01);
  add(Body::organ_coarse, "OrganCoarse", 0.8, "at80", 0.06, "6cmps", 0.01);
  // The organ (52k tets, about a second a step with exact solves): TISSUE_SEPARATION_ORGAN=1.
  if (const char* organ = std::getenv("TISSUE_SEPARATION_ORGAN"); organ != nullptr && *organ == '1') {
    add(Body::organ, "Organ", 0.55, "at55", 0.2, "20cmps", 0.01);
  }
  for (const auto& [plane, plane_name] : {std::pair{0.45, "at45"}, std::pair{0.55, "at55"}, std::pair{0.65, "at65"}}) {
    add(Body::frog, "Frog", plane, plane_name, 0.02, "2cmps", 0.01);
    add(Body::frog, "Frog", plane, plane_name, 0.2, "20cmps", 0.01);
  }
  add(Body::frog, "Frog", 0.55, "at55", 0.01, "1cmps", 0.01);
  add(Body::frog, "Frog", 0.55, "at55", 1.0, "1mps", 0.01);
  add(Body::frog, "Frog", 0.55, "at55", 0.02, "2cmpsIn2msSteps", 0.002);
  for (const auto& [plane, plane_name] :
       {std::pair{10.0, "onLayer"}, std::pair{10.001, "past0p1pct"}, std::pair{10.06, "past6pct"}, std::pair{10.5, "midLayer"}}) {
    add(Body::beam_5mm, "Beam5mm", plane, plane_name, 0.02, "2cmps", 0.01);
    add(Body::beam_5mm, "Beam5mm", plane, plane_name, 0.2, "20cmps", 0.01);
  }
  add(Body::beam_5mm, "Beam5mm", 10.001, "past0p1pct", 0.5, "50cmps", 0.01);
  for (const auto& [plane, plane_name] : {std::pair{5.0, "onLayer"}, std::pair{5.001, "past0p1pct"}, std::pair{5.5, "midLayer"}}) {
    add(Body::beam_1cm, "Beam1cm", plane, plane_name, 0.01, "1cmps", 0.01);
    add(Body::beam_1cm, "Beam1cm", plane, plane_name, 0.0101, "1p01cmps", 0.01);
    add(Body::beam_1cm, "Beam1cm", plane, plane_name, 1.0, "1mps", 0.01);
  }
  return all;
}

INSTANTIATE_TEST_SUITE_P(Matrix, StrokeSeparation, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& param_info) { return param_info.param.name; });

}  // namespace
}  // namespace tissue
