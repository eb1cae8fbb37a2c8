// Inputs that are not numbers. A tool pose with a NaN or infinite position or quaternion, or a
// zero quaternion, is refused by set_tool() with a ParameterError and changes nothing: the tool,
// the time and the state stay as they were, and the next step goes on from them. Settings that
// are NaN, infinite, negative or out of range are refused by validate() and by the Tissue's
// constructor with a ParameterError, for every integrator.
#include "extremes_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace tissue::extremes {
namespace {

constexpr double NOT_A_NUMBER = std::numeric_limits<double>::quiet_NaN();
constexpr double INFINITE = std::numeric_limits<double>::infinity();

class BadInputs : public ::testing::TestWithParam<Method> {};

bool same(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

TEST_P(BadInputs, ToolPoseIsRefusedAndChangesNothing) {
  const Method method = GetParam();
  extremes::Run run("BadToolPose/" + std::string(method_id(method)), method, pad());
  ASSERT_TRUE(run.running());
  // The probe pressed 2 mm into the pad: a state with a contact, velocities and a deformation.
  const Eigen::Vector3d top(PAD_X_M, PAD_Y_M, PAD_TOP_M);
  const ToolPose pressed{top - Eigen::Vector3d(0.0, 0.0, 0.002), Eigen::Quaterniond::Identity(), ToolMode::probe};
  run.step_with({top + Eigen::Vector3d(0.0, 0.0, 0.002), Eigen::Quaterniond::Identity(), ToolMode::probe});
  move_tool(run, pressed.tip_position_m, 1.0, ToolMode::probe);
  ASSERT_TRUE(run.running()) << run.outcome().reason;
  Tissue& tissue = run.tissue();
  ASSERT_TRUE(tissue.contact().active);

  std::vector<ToolPose> bad;
  for (const double value : {NOT_A_NUMBER, INFINITE, -INFINITE}) {
    for (int axis = 0; axis < 3; ++axis) {
      ToolPose pose = pressed;
      pose.tip_position_m(axis) = value;
      bad.push_back(pose);
    }
    for (int k = 0; k < 4; ++k) {
      ToolPose pose = pressed;
      pose.orientation.coeffs()(k) = value;
      bad.push_back(pose);
    }
  }
  for (const double tiny : {0.0, 1e-200, -0.0}) {
    ToolPose pose = pressed;
    pose.orientation = Eigen::Quaterniond(tiny, tiny, 0.0, 0.0);
    bad.push_back(pose);
  }
  const ToolPose tool_before = tissue.tool();
  const double time_before = tissue.time_s();
  const Eigen::VectorXd displacement_before = tissue.state().displacement_m;
  const Eigen::VectorXd velocity_before = tissue.state().velocity_m_per_s;
  int refused = 0;
  for (const ToolPose& pose : bad) {
    try {
      tissue.set_tool(pose);
    } catch (const ParameterError&) {
      ++refused;
    }
    EXPECT_EQ(tissue.tool().tip_position_m, tool_before.tip_position_m);
    EXPECT_EQ(tissue.tool().orientation.coeffs(), tool_before.orientation.coeffs());
    EXPECT_EQ(tissue.tool().mode, tool_before.mode);
  }
  EXPECT_EQ(refused, static_cast<int>(bad.size()));
  EXPECT_EQ(tissue.time_s(), time_before);
  EXPECT_TRUE(same(tissue.state().displacement_m, displacement_before));
  EXPECT_TRUE(same(tissue.state().velocity_m_per_s, velocity_before));
  // The next steps go on from the kept pose and state.
  run.steps(5);
  const Outcome outcome = run.finish();
  EXPECT_EQ(outcome.kind, Outcome::Kind::ok) << outcome.reason;
  EXPECT_TRUE(tissue.contact().active);
  record_cell("bad tool pose: NaN / +-Inf position or quaternion, zero or 1e-200 quaternion", method,
              "refused: ParameterError for " + std::to_string(refused) + " of " + std::to_string(bad.size()) +
                  " poses; tool, time and state kept, the next 5 steps ok");
}

TEST_P(BadInputs, SettingsAreRefusedWhenGiven) {
  const Method method = GetParam();
  using Change = std::function<void(TissueSettings&)>;
  const std::vector<Change> changes{
      [](TissueSettings& s) { s.step_size_s = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.step_size_s = INFINITE; },
      [](TissueSettings& s) { s.step_size_s = -1e-3; },
      [](TissueSettings& s) { s.body.material.young_modulus_pa = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.body.material.young_modulus_pa = -1e5; },
      [](TissueSettings& s) { s.body.material.young_modulus_pa = INFINITE; },
      [](TissueSettings& s) { s.body.material.poisson_ratio = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.body.material.poisson_ratio = -0.1; },
      [](TissueSettings& s) { s.body.material.poisson_ratio = 0.5; },
      [](TissueSettings& s) { s.body.material.density_kg_per_m3 = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.body.material.density_kg_per_m3 = 0.0; },
      [](TissueSettings& s) { s.body.damping.mass_damping_per_s = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.body.damping.mass_damping_per_s = -1.0; },
      [](TissueSettings& s) { s.body.damping.stiffness_damping_s = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.body.damping.stiffness_damping_s = -1e-3; },
      [](TissueSettings& s) { s.body.gravity_m_per_s2.z() = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.body.gravity_m_per_s2.x() = INFINITE; },
      [](TissueSettings& s) { s.solver.pcg.tolerance = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.solver.pcg.tolerance = -1e-3; },
      [](TissueSettings& s) { s.solver.pcg.max_iterations = 0; },
      [](TissueSettings& s) { s.integrator.ida.relative_tolerance = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.integrator.ida.relative_tolerance = -1e-4; },
      [](TissueSettings& s) { s.integrator.ida.absolute_tolerance = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.integrator.ida.absolute_tolerance = 0.0; },
      [](TissueSettings& s) { s.integrator.ida.max_step_s = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.integrator.ida.max_step_s = -1.0; },
      [](TissueSettings& s) { s.integrator.ida.max_order = 0; },
      [](TissueSettings& s) { s.integrator.ida.max_internal_steps = 0; },
      [](TissueSettings& s) { s.interaction.blade_length_m = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.interaction.blade_length_m = -0.03; },
      [](TissueSettings& s) { s.interaction.contact.spring_stiffness_n_per_m = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.interaction.contact.spring_stiffness_n_per_m = -1.0; },
      [](TissueSettings& s) { s.interaction.contact.spring_stiffness_n_per_m = INFINITE; },
      [](TissueSettings& s) { s.interaction.max_tool_speed_m_per_s = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.interaction.max_tool_speed_m_per_s = -5.0; },
      [](TissueSettings& s) { s.interaction.max_tool_speed_m_per_s = 0.0; },
      [](TissueSettings& s) { s.interaction.max_tool_speed_m_per_s = INFINITE; },
      [](TissueSettings& s) { s.interaction.contact.stiffness_refresh_steps = 0; },
      [](TissueSettings& s) { s.interaction.cutter.min_volume_fraction = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.interaction.cutter.min_volume_fraction = -1e-3; },
      [](TissueSettings& s) { s.interaction.cutter.vertex_snap_fraction = NOT_A_NUMBER; },
      [](TissueSettings& s) { s.interaction.cutter.vertex_snap_fraction = -1e-3; },
      [](TissueSettings& s) { s.body.fixed_vertices = {-1}; },
  };
  int refused_by_validate = 0, refused_when_built = 0;
  for (size_t k = 0; k < changes.size(); ++k) {
    Scene scene = pad();
    use_method(scene.settings, method);
    changes[k](scene.settings);
    // validate() checks the settings alone; fixed vertex ids need the mesh (the body checks them).
    const bool mesh_dependent = k + 1 == changes.size();
    if (!mesh_dependent) {
      try {
        validate(scene.settings);
        ADD_FAILURE() << "validate() accepted bad setting " << k;
      } catch (const ParameterError&) {
        ++refused_by_validate;
      }
    }
    try {
      Tissue tissue(std::move(scene.mesh), std::move(scene.settings));
      ADD_FAILURE() << "the Tissue accepted bad setting " << k;
    } catch (const ParameterError&) {
      ++refused_when_built;
    } catch (const std::exception& error) {
      ADD_FAILURE() << "bad setting " << k << " threw something other than a ParameterError: " << error.what();
    }
  }
  EXPECT_EQ(refused_when_built, static_cast<int>(changes.size()));
  record_cell("bad settings: NaN, Inf, negative or out of range (" + std::to_string(changes.size()) + " kinds)", method,
              "refused: ParameterError for " + std::to_string(refused_when_built) + " of " +
                  std::to_string(changes.size()) + " (validate(): " + std::to_string(refused_by_validate) + " of " +
                  std::to_string(changes.size() - 1) + ", the last needs the mesh)");
}

INSTANTIATE_TEST_SUITE_P(Extremes, BadInputs, ::testing::ValuesIn(ALL_METHODS),
                         [](const auto& param_info) { return std::string(method_id(param_info.param)); });

}  // namespace
}  // namespace tissue::extremes
