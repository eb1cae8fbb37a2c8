// Extremes of the tool's motion: a hand at 10 m/s (twice the Tissue's default limit) dragging the
// probe over the surface, pushing it into the body, drawing the scalpel through it, and a tool
// that teleports (a pose 0.5 m away in one step, into and out of the body, and through it). Each
// with the default tool-speed limit (5 m/s: the tool the Tissue applies lags the hand and catches
// up) and with a limit of 1e6 m/s (the tool goes where it is put). Scene: a pad of 6 x 4 x 2 cubes
// of 1 cm held at its bottom (gravity on), and the frog for the scalpel. Energy bound: the work of
// gravity and of the probe's spring on the body (extremes_support.hpp).
#include "extremes_support.hpp"

#include <gtest/gtest.h>

#include <string>
#include <tuple>
#include <vector>

namespace tissue::extremes {
namespace {

constexpr double HAND_SPEED_M_PER_S = 10.0;
// How far the tool teleports: 0.5 m; 0.1 m under sanitizers (at the 5 m/s limit each jump is
// approached over distance / 5 mm steps: 100 of them, and IDA crawls through the crushed pad).
constexpr double TELEPORT_M = UNDER_SANITIZER ? 0.1 : 0.5;
constexpr double LARGE_LIMIT_M_PER_S = 1e6;

ToolPose probe_at(const Eigen::Vector3d& tip) { return {tip, Eigen::Quaterniond::Identity(), ToolMode::probe}; }
ToolPose scalpel_at(const Eigen::Vector3d& tip) { return {tip, Eigen::Quaterniond::Identity(), ToolMode::scalpel}; }
ToolPose away(const Eigen::Vector3d& tip) { return {tip, Eigen::Quaterniond::Identity(), ToolMode::none}; }

// The probe lowered 2 mm into the pad, dragged 4.4 cm along x, lifted; then 50 steps.
void drag_probe(Run& run) {
  const Eigen::Vector3d start(0.008, PAD_Y_M, PAD_TOP_M + 0.005);
  if (!run.step_with(probe_at(start))) return;
  move_tool(run, Eigen::Vector3d(0.008, PAD_Y_M, PAD_TOP_M - 0.002), HAND_SPEED_M_PER_S, ToolMode::probe);
  move_tool(run, Eigen::Vector3d(0.052, PAD_Y_M, PAD_TOP_M - 0.002), HAND_SPEED_M_PER_S, ToolMode::probe);
  move_tool(run, Eigen::Vector3d(0.052, PAD_Y_M, PAD_TOP_M + 0.005), HAND_SPEED_M_PER_S, ToolMode::probe);
  run.steps(phase_steps(50));
}

// The probe pushed 1 cm into the 2 cm pad, held 30 steps, withdrawn; then 30 steps.
void push_probe(Run& run) {
  const Eigen::Vector3d above(PAD_X_M, PAD_Y_M, PAD_TOP_M + 0.005);
  if (!run.step_with(probe_at(above))) return;
  move_tool(run, Eigen::Vector3d(PAD_X_M, PAD_Y_M, PAD_TOP_M - 0.01), HAND_SPEED_M_PER_S, ToolMode::probe);
  run.steps(phase_steps(30));
  move_tool(run, above, HAND_SPEED_M_PER_S, ToolMode::probe);
  run.steps(phase_steps(30));
}

// A vertical scalpel (tip 5 mm above the held bottom, 3 cm blade) drawn across the pad; put away;
// then 50 steps.
void draw_scalpel(Run& run) {
  if (!run.step_with(scalpel_at(Eigen::Vector3d(PAD_X_M, -0.01, 0.005)))) return;
  move_tool(run, Eigen::Vector3d(PAD_X_M, 0.05, 0.005), HAND_SPEED_M_PER_S, ToolMode::scalpel);
  run.step_with(away(Eigen::Vector3d(PAD_X_M, 0.05, 0.005)));
  run.steps(phase_steps(50));
}

// Steps until the applied tool has reached the pose set (at once without a limit; 0.5 m at the
// default 5 m/s takes 100 steps of 1 ms), then `extra` more.
void arrive_and_hold(Run& run, int extra) {
  for (int k = 0; k < 200 && run.running(); ++k) {
    if (run.tissue().applied_tool().tip_position_m == run.tissue().tool().tip_position_m) break;
    run.step();
  }
  if (run.running() && run.tissue().applied_tool().tip_position_m != run.tissue().tool().tip_position_m) {
    run.fail("the applied tool did not reach the pose set within 200 steps");
  }
  run.steps(extra);
}

// The probe TELEPORT_M above the pad, then set 1 cm deep into it (one step without a limit); held
// 20 steps; set TELEPORT_M up and out; 10 steps; then set TELEPORT_M straight through the pad to
// below it (entering from the top, ending TELEPORT_M / 2 below the held bottom); 20 steps.
void teleport_probe(Run& run) {
  const Eigen::Vector3d inside(PAD_X_M, PAD_Y_M, PAD_TOP_M - 0.01);  // half way down
  const Eigen::Vector3d far_above = inside + Eigen::Vector3d(0.0, 0.0, TELEPORT_M);
  if (!run.step_with(probe_at(far_above))) return;
  run.set_tool(probe_at(inside));
  arrive_and_hold(run, phase_steps(20));
  run.set_tool(probe_at(far_above));
  arrive_and_hold(run, phase_steps(10));
  run.step_with(probe_at(Eigen::Vector3d(PAD_X_M, PAD_Y_M, 0.5 * TELEPORT_M)));
  arrive_and_hold(run, 0);
  run.set_tool(probe_at(Eigen::Vector3d(PAD_X_M, PAD_Y_M, -0.5 * TELEPORT_M)));
  arrive_and_hold(run, phase_steps(20));
}

// The scalpel TELEPORT_M to the side, then set into the middle of the pad; 5 steps; set TELEPORT_M
// on and out the other side; put away; 30 steps.
void teleport_scalpel(Run& run) {
  const Eigen::Vector3d inside(PAD_X_M, PAD_Y_M, 0.005);
  if (!run.step_with(scalpel_at(inside - Eigen::Vector3d(0.0, TELEPORT_M, 0.0)))) return;
  run.set_tool(scalpel_at(inside));
  arrive_and_hold(run, phase_steps(5));
  const Eigen::Vector3d beyond = inside + Eigen::Vector3d(0.0, TELEPORT_M, 0.0);
  run.set_tool(scalpel_at(beyond));
  arrive_and_hold(run, phase_steps(5));
  run.step_with(away(beyond));
  run.steps(phase_steps(30));
}

// The frog: a vertical scalpel (tip 1 cm above the tray, above the held 25%) drawn across the
// body behind the forelegs at the hand's speed (under sanitizers to the middle only: IDA takes ~1 s
// a step there); put away; 10 steps.
void draw_scalpel_through_frog(Run& run) {
  const double end_y = UNDER_SANITIZER ? 0.0 : 0.06;
  if (!run.step_with(scalpel_at(Eigen::Vector3d(0.0051, -0.06, 0.01)))) return;
  move_tool(run, Eigen::Vector3d(0.0051, end_y, 0.01), HAND_SPEED_M_PER_S, ToolMode::scalpel);
  run.step_with(away(Eigen::Vector3d(0.0051, end_y, 0.01)));
  run.steps(phase_steps(10));
}

Case tool_case(std::string id, std::string label, std::function<Scene()> make_scene, std::function<void(Run&)> script,
               bool large_limit) {
  Case c;
  c.id = std::move(id) + (large_limit ? "NoLimit" : "Limit5");
  c.label = std::move(label) + (large_limit ? ", limit 1e6 m/s" : ", limit 5 m/s");
  c.scene = [make_scene = std::move(make_scene), large_limit] {
    Scene scene = make_scene();
    if (large_limit) scene.settings.interaction.max_tool_speed_m_per_s = LARGE_LIMIT_M_PER_S;
    return scene;
  };
  c.script = std::move(script);
  return c;
}

const std::vector<Case>& cases() {
  static const std::vector<Case> all = [] {
    std::vector<Case> list;
    const std::string distance = UNDER_SANITIZER ? "0.1 m" : "0.5 m";
    for (const bool large_limit : {false, true}) {
      list.push_back(tool_case("PadProbeDrag", "pad: probe dragged 2 mm deep at 10 m/s", pad, drag_probe, large_limit));
      list.push_back(
          tool_case("PadProbePush", "pad: probe pushed 1 cm into 2 cm at 10 m/s", pad, push_probe, large_limit));
      list.push_back(tool_case("PadScalpel", "pad: scalpel drawn through at 10 m/s", pad, draw_scalpel, large_limit));
      list.push_back(tool_case("PadProbeTeleport", "pad: probe teleported " + distance + " in, out, through", pad,
                               teleport_probe, large_limit));
      // Set through the pad, the probe's spring (25 cm long) crushes it flat against its held
      // bottom, tets inverted: IDA's error control crawls there.
      list.back().may_refuse = {Method::ida_klu, Method::ida_krylov};
      list.back().refusal_note = "IDA crawls once the pad is crushed flat (tets inverted)";
      list.push_back(tool_case("PadScalpelTeleport", "pad: scalpel teleported " + distance + " in and out", pad,
                               teleport_scalpel, large_limit));
    }
    // The frog's irregular mesh once (IDA takes 10-50 ms a step on its 2088 unknowns).
    list.push_back(tool_case(
        "FrogScalpel",
        UNDER_SANITIZER ? "frog: scalpel drawn half way through at 10 m/s" : "frog: scalpel drawn through at 10 m/s",
        frog_on_tray, draw_scalpel_through_frog, false));
    return list;
  }();
  return all;
}

TISSUE_EXTREMES_SUITE(ToolSpeed, cases);

}  // namespace
}  // namespace tissue::extremes
