// Scripted scalpel cuts through the frog (frame: x tail to head, y to the left, z up, metres),
// the dissertation's table 6.3 test cases 2-7 redone on our frog, for tissue-cut-bench and the demo.
// A cut is a straight stroke of a vertical scalpel (tool axis +z) from `from` to `to` in the
// x-y plane, starting and ending outside the body, at a given speed.
#pragma once

#include "core/tissue.hpp"

#include <Eigen/Core>

#include <functional>
#include <string>
#include <vector>

namespace tissue::apps {

struct CutStroke {
  std::string name;
  Eigen::Vector2d from_m;
  Eigen::Vector2d to_m;
};

struct CutScenario {
  std::string name;
  std::vector<CutStroke> strokes;
};

/// Test 2-7 of table 6.3 on our frog: 1, 1, 1, 2, 2 and 3 complete cuts.
std::vector<CutScenario> frog_cut_scenarios();

struct StrokeSettings {
  double speed_m_per_s = 0.2;
  double tip_height_m = -0.01;  ///< z of the blade tip, below the frog (the blade spans the body)
};

/// Drives `tissue` through one stroke: scalpel steps from `from` to `to` at the speed, then one
/// step with the tool put away. `on_step` sees every step's report. Returns the number of steps.
int run_stroke(Tissue& tissue, const CutStroke& stroke, const StrokeSettings& settings,
               const std::function<void(const TissueStepReport&)>& on_step);

}  // namespace tissue::apps
