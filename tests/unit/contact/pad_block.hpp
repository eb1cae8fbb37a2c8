// The scene the pad tests share (point_contact.hpp, "A pad"): a 6 x 6 x 3 cm block of E 100 kPa, nu
// 0.45 held by its base, stepped quasi-statically (exact solves, 50 ms steps, mass damping 20 /s),
// and a probe pressed straight down into its top.
#pragma once

#include "core/mesh/box_mesh.hpp"
#include "core/tissue.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <memory>

namespace tissue::pad_test {

inline constexpr double BLOCK_M = 0.06;
inline constexpr double DEPTH_M = 0.03;
inline constexpr double PRESS_M = 2e-3;

inline ToolPose probe_at(const Eigen::Vector3d& position_m) {
  return ToolPose{position_m, Eigen::Quaterniond::Identity(), ToolMode::probe};
}

inline TissueSettings block_settings(double pad_radius_m) {
  TissueSettings settings;
  settings.body.material = Material{1.0e5, 0.45, 1000.0};
  settings.body.gravity_m_per_s2.setZero();
  settings.body.damping.mass_damping_per_s = 20.0;  // quasi-static: the block settles within the hold
  settings.body.damping.stiffness_damping_s = 0.0;
  settings.solver.kind = LinearSolverKind::cholmod;
  settings.step_size_s = 0.05;
  settings.interaction.cutting_enabled = false;
  settings.interaction.contact.pad_radius_m = pad_radius_m;
  return settings;
}

/// The block in cubes of `edge_m`, probed by a pad of `pad_radius_m` (0: a point).
inline std::unique_ptr<Tissue> block(double edge_m, double pad_radius_m) {
  const int across = static_cast<int>(std::lround(BLOCK_M / edge_m));
  const int deep = static_cast<int>(std::lround(DEPTH_M / edge_m));
  const TetMesh mesh = make_box_mesh(across, across, deep, edge_m);
  TissueSettings settings = block_settings(pad_radius_m);
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    if (mesh.rest_positions_m[static_cast<size_t>(v)].z() < 1e-9) settings.body.fixed_vertices.push_back(v);
  }
  return std::make_unique<Tissue>(mesh, settings);
}

/// The probe lowered over 10 steps to `press_m` below the top at (x, y), held 30 steps; the force
/// along z.
inline double pressed_force_n(Tissue& tissue, double x_m, double y_m, double press_m) {
  for (int s = 0; s <= 10; ++s) {
    tissue.set_tool(probe_at({x_m, y_m, DEPTH_M + 1e-3 - (1e-3 + press_m) * s / 10.0}));
    tissue.step();
  }
  for (int s = 0; s < 30; ++s) tissue.step();
  EXPECT_TRUE(tissue.contact().active);
  return tissue.contact().force_on_tool_n.z();
}

}  // namespace tissue::pad_test
