// The pieces of tissue-host compare without running an FMU (host/compare):
// * the errors against the reference are the RMS and maximum of |x - x_ref| over points and
//   vertices, the RMS of the force difference, the largest energy difference; a run that does not
//   line up with the reference in time or points is not compared;
// * the Pareto front keeps exactly the undominated points;
// * a CSV row read back is the row written, bit for bit (the MPI gather relies on it);
// * recommendations respect the use's step and cost bounds, and say when nothing qualifies;
// * the settings: the default list, steps that divide the communication step, the [compare]
//   table, parameters the FMU lacks (refused for a user's setting, a skipped row for a built-in
//   one, the built-in reference falling back to backward Euler with CHOLMOD);
// * the plot has its size, the series' colours, the rings of the front, and text; the font has a
//   glyph for every printable character.
#include "compare/compare_metrics.hpp"
#include "compare/compare_report.hpp"
#include "compare/compare_settings.hpp"
#include "compare/compare_table.hpp"
#include "compare/plot_png.hpp"
#include "compare/recommendation.hpp"
#include "host_test_support.hpp"
#include "importer/model_description.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <limits>
#include <set>

namespace tissue::host {
namespace {

using test::model_description_xml;
using test::TempDir;
using test::write_file;

// --- metrics ---

ReferenceTrace two_point_trace() {
  ReferenceTrace trace;
  trace.vertex_count = 2;
  trace.add(0.01, std::vector<double>{0, 0, 0, 1, 0, 0, 9, 9, 9}, {1.0, 0.0, 0.0}, 2.0);  // a third row: a cut corner
  trace.add(0.02, std::vector<double>{0, 0, 1, 1, 0, 1}, {2.0, 0.0, 0.0}, 3.0);
  return trace;
}

TEST(CompareMetrics, ErrorsAreRmsAndMaximaOverPointsAndOriginalVertices) {
  const ReferenceTrace reference = two_point_trace();
  ASSERT_EQ(reference.positions_m.size(), 12u);  // the cut corner is not recorded
  ErrorAccumulator compare(reference);
  // Point 1: vertex 0 off by 3e-3 along x, vertex 1 exact; point 2: both off by 4e-3 along z.
  compare.add(0.01, std::vector<double>{3e-3, 0, 0, 1, 0, 0, 5, 5, 5}, {1.0, 3.0, 0.0}, 2.5);
  compare.add(0.02, std::vector<double>{0, 0, 1.004, 1, 0, 1.004}, {2.0, 0.0, 4.0}, 2.0);
  const ErrorMetrics e = compare.result();
  ASSERT_TRUE(e.valid) << e.why_not;
  EXPECT_NEAR(e.rms_error_m, std::sqrt((9e-6 + 0 + 16e-6 + 16e-6) / 4.0), 1e-15);
  EXPECT_NEAR(e.max_error_m, 4e-3, 1e-15);
  EXPECT_NEAR(e.force_error_n, std::sqrt((9.0 + 16.0) / 2.0), 1e-15);
  EXPECT_NEAR(e.energy_drift_j, 1.0, 1e-15);
}

TEST(CompareMetrics, TheReferenceAgainstItselfIsExactlyZero) {
  const ReferenceTrace reference = two_point_trace();
  ErrorAccumulator compare(reference);
  compare.add(0.01, std::vector<double>(reference.positions_m.begin(), reference.positions_m.begin() + 6),
              {1.0, 0.0, 0.0}, 2.0);
  compare.add(0.02, std::vector<double>(reference.positions_m.begin() + 6, reference.positions_m.end()),
              {2.0, 0.0, 0.0}, 3.0);
  const ErrorMetrics e = compare.result();
  ASSERT_TRUE(e.valid);
  EXPECT_EQ(e.rms_error_m, 0.0);
  EXPECT_EQ(e.max_error_m, 0.0);
  EXPECT_EQ(e.force_error_n, 0.0);
  EXPECT_EQ(e.energy_drift_j, 0.0);
}

TEST(CompareMetrics, ARunThatDoesNotLineUpWithTheReferenceIsNotCompared) {
  const ReferenceTrace reference = two_point_trace();
  const std::vector<double> x{0, 0, 0, 1, 0, 0};
  {
    ErrorAccumulator stopped(reference);  // an error after the first step
    stopped.add(0.01, x, {}, 0.0);
    const ErrorMetrics e = stopped.result();
    EXPECT_FALSE(e.valid);
    EXPECT_NE(e.why_not.find("stopped after 1 of 2"), std::string::npos) << e.why_not;
  }
  {
    ErrorAccumulator discarded(reference);  // a discarded step: the next point at another time
    discarded.add(0.015, x, {}, 0.0);
    discarded.add(0.025, x, {}, 0.0);
    const ErrorMetrics e = discarded.result();
    EXPECT_FALSE(e.valid);
    EXPECT_NE(e.why_not.find("discarded"), std::string::npos) << e.why_not;
  }
  {
    ErrorAccumulator fewer(reference);
    fewer.add(0.01, std::vector<double>{0, 0, 0}, {}, 0.0);
    EXPECT_FALSE(fewer.result().valid);
  }
}

TEST(CompareMetrics, TheTraceTravelsExactly) {
  ReferenceTrace trace = two_point_trace();
  trace.positions_m[1] = 0.1 + 0.2;
  trace.energy_j[0] = std::numeric_limits<double>::denorm_min();
  const std::string bytes = trace.to_bytes();
  const ReferenceTrace back = ReferenceTrace::from_bytes(bytes);
  EXPECT_EQ(back.vertex_count, trace.vertex_count);
  EXPECT_EQ(back.time_s, trace.time_s);
  EXPECT_EQ(back.positions_m, trace.positions_m);
  EXPECT_EQ(back.force_n, trace.force_n);
  EXPECT_EQ(back.energy_j, trace.energy_j);
  EXPECT_THROW((void)ReferenceTrace::from_bytes(bytes.substr(0, bytes.size() - 3)), std::runtime_error);
  EXPECT_THROW((void)ReferenceTrace::from_bytes("not a trace"), std::runtime_error);
}

TEST(CompareMetrics, TheParetoFrontKeepsTheUndominatedPoints) {
  const std::vector<double> cost{1, 2, 3, 4, 5, 0.5, 2};
  const std::vector<double> error{10, 5, 5, 1, 2, 0.1, 5};
  // Point 5 would dominate everything but is ineligible; 2 is dominated by 1 (same error, more
  // costly); 4 by 3; 6 ties with 1 exactly (neither dominates the other).
  const std::vector<bool> front = pareto_front(cost, error, {true, true, true, true, true, false, true});
  EXPECT_EQ(front, (std::vector<bool>{true, true, false, true, false, false, true}));
}

// --- CSV ---

CompareRow sample_row() {
  CompareRow row;
  row.setting = "be-pcg-tol1e-3-cap10";
  row.integrator = "backwardEuler";
  row.linear_solver = "pcg";
  row.tolerance = 1e-3;
  row.iteration_cap = 10;
  row.internal_step_s = 0.001;
  row.cpu_s_per_sim_s = 0.1 + 0.2;
  row.rms_error_m = 1.2345678901234567e-7;
  row.max_error_m = std::numeric_limits<double>::denorm_min();
  row.force_error_n = 1e300;
  row.energy_drift_j = 0.0;
  row.iterations = 18446744073709551615ULL;
  row.failures = 2;
  row.pareto = true;
  row.note = "doStep: \"discard\", then\nan error";
  return row;
}

TEST(CompareTable, ARowReadBackIsTheRowWrittenBitForBit) {
  const CompareRow row = sample_row();
  const std::string line = csv_row(row);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const CompareRow back = parse_csv_row(line);
  EXPECT_EQ(back.setting, row.setting);
  EXPECT_EQ(back.tolerance, row.tolerance);
  EXPECT_EQ(back.iteration_cap, row.iteration_cap);
  EXPECT_EQ(back.internal_step_s, row.internal_step_s);
  EXPECT_EQ(back.cpu_s_per_sim_s, row.cpu_s_per_sim_s);
  EXPECT_EQ(back.rms_error_m, row.rms_error_m);
  EXPECT_EQ(back.max_error_m, row.max_error_m);
  EXPECT_EQ(back.force_error_n, row.force_error_n);
  EXPECT_EQ(back.energy_drift_j, row.energy_drift_j);
  EXPECT_EQ(back.iterations, row.iterations);
  EXPECT_EQ(back.failures, 2u);
  EXPECT_TRUE(back.pareto);
  EXPECT_EQ(back.note, "doStep: \"discard\", then an error");
  EXPECT_EQ(csv_row(back), line);
}

TEST(CompareTable, MissingValuesAreEmptyFields) {
  CompareRow row;
  row.setting = "be-cholmod";
  row.integrator = "backwardEuler";
  row.linear_solver = "cholmod";
  row.internal_step_s = 0.01;
  const std::string line = csv_row(row);
  EXPECT_EQ(line, "be-cholmod,backwardEuler,cholmod,corotationalLinear,,,0.01,,,,,,,0,0,");
  const CompareRow back = parse_csv_row(line);
  EXPECT_FALSE(back.tolerance);
  EXPECT_FALSE(back.rms_error_m);
  EXPECT_FALSE(back.comparable());
  EXPECT_THROW((void)parse_csv_row("a,b,c"), std::runtime_error);
  EXPECT_THROW((void)parse_csv_row("a,b,c,d,x,,0.01,,,,,,,0,0,"), std::runtime_error);
}

// --- recommendations ---

CompareRow candidate(std::string name, double step_s, double cost, double error) {
  CompareRow row;
  row.setting = std::move(name);
  row.integrator = "backwardEuler";
  row.linear_solver = "pcg";
  row.internal_step_s = step_s;
  row.cpu_s_per_sim_s = cost;
  row.rms_error_m = error;
  return row;
}

TEST(Recommendation, EachUseGetsTheLowestErrorWithinItsBounds) {
  std::vector<CompareRow> rows{
      candidate("reference", 1e-3, 9.0, 0.0),  // never recommended
      candidate("fast", 1e-3, 0.1, 1e-4),     candidate("good", 1e-3, 0.4, 1e-5),
      candidate("too-slow", 1e-3, 0.6, 1e-6),                                              // over 0.5 CPU s per s
      candidate("coarse", 1e-2, 0.05, 5e-6),                                               // 10 ms: visual only
      candidate("failed", 1e-3, 0.1, 1e-9),   candidate("exact-twin", 1e-2, 0.01, 5e-6)};  // same error, cheaper
  rows[5].failures = 1;
  const std::vector<Recommendation> r = recommend(rows);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[0].use.name, "1 kHz haptic");
  ASSERT_TRUE(r[0].row);
  EXPECT_EQ(rows[*r[0].row].setting, "good");
  ASSERT_TRUE(r[1].row);
  EXPECT_EQ(rows[*r[1].row].setting, "exact-twin");  // tie on error goes to the cheaper
  ASSERT_TRUE(r[2].row);
  EXPECT_EQ(rows[*r[2].row].setting, "too-slow");  // offline: any cost
  EXPECT_NE(r[0].text.find("good @ 1 ms"), std::string::npos) << r[0].text;
}

TEST(Recommendation, SaysWhenNoSettingQualifies) {
  const std::vector<CompareRow> rows{candidate("reference", 1e-3, 9.0, 0.0), candidate("slow", 1e-3, 2.0, 1e-5)};
  const std::vector<Recommendation> r = recommend(rows);
  EXPECT_FALSE(r[0].row);
  EXPECT_NE(r[0].text.find("no setting qualifies"), std::string::npos) << r[0].text;
  EXPECT_FALSE(r[1].row);
  ASSERT_TRUE(r[2].row);
  EXPECT_EQ(rows[*r[2].row].setting, "slow");
}

// --- settings ---

// A Tissue-like description: the PCG/CHOLMOD parameters, and with_ida also integrator.method.
ModelDescription tissue_like(bool with_ida) {
  const std::string types = R"(<TypeDefinitions>
    <EnumerationType name="LinearSolver"><Item name="pcg" value="1"/><Item name="cholmod" value="2"/><Item name="pcgCholesky" value="3"/><Item name="pcgTwoLevel" value="4"/></EnumerationType>
    <EnumerationType name="Integrator"><Item name="backwardEuler" value="1"/><Item name="ida" value="2"/></EnumerationType>
    <EnumerationType name="IdaLinearSolver"><Item name="klu" value="1"/><Item name="krylov" value="2"/></EnumerationType>
  </TypeDefinitions>)";
  std::string variables = R"(
    <Enumeration name="integrator.linearSolver" valueReference="10" causality="parameter" variability="fixed" declaredType="LinearSolver" start="1"/>
    <Float64 name="integrator.pcgTolerance" valueReference="11" causality="parameter" variability="fixed" start="0.001"/>
    <Int32 name="integrator.pcgMaxIterations" valueReference="12" causality="parameter" variability="fixed" start="10"/>
    <Boolean name="integrator.warmStart" valueReference="13" causality="parameter" variability="fixed" start="false"/>
    <Int32 name="integrator.newtonMaxIterations" valueReference="86" causality="parameter" variability="fixed" start="1"/>
    <Boolean name="integrator.linearizeAtPredictedEnd" valueReference="92" causality="parameter" variability="fixed" start="true"/>
    <Float64 name="stepSize" valueReference="14" causality="parameter" variability="fixed" start="0.001"/>
    <Float64 name="contact.force" valueReference="43" causality="output" variability="continuous"/>)";
  if (with_ida) {
    variables += R"(
    <Enumeration name="integrator.method" valueReference="70" causality="parameter" variability="fixed" declaredType="Integrator" start="1"/>
    <Float64 name="integrator.idaRelativeTolerance" valueReference="71" causality="parameter" variability="fixed" start="0.0001"/>
    <Float64 name="integrator.idaAbsoluteTolerance" valueReference="72" causality="parameter" variability="fixed" start="1e-08"/>
    <Float64 name="integrator.idaMaxStep" valueReference="74" causality="parameter" variability="fixed" start="0"/>
    <Enumeration name="integrator.idaLinearSolver" valueReference="75" causality="parameter" variability="fixed" declaredType="IdaLinearSolver" start="1"/>)";
  }
  return parse_model_description(model_description_xml(variables, types));
}

Scenario scenario_with_step(double communication_step_s) {
  Scenario s;
  s.file = "test.toml";
  s.tissue_step_s = communication_step_s;
  return s;
}

TEST(CompareSettings, TheDefaultListAndSteps) {
  const CompareSettingsList list = default_settings();
  std::vector<std::string> names;
  for (const CompareSetting& s : list.settings) names.push_back(s.name);
  EXPECT_EQ(names, (std::vector<std::string>{
                       "be-pcgTwoLevel-tol1e-3-cap10", "be-pcgTwoLevel-tol1e-3-cap10-atStart", "be-pcg-tol1e-3-cap10",
                       "be-pcg-tol1e-6-cap1000", "be-pcgCholesky-tol1e-5-cap25", "be-pcgTwoLevel-tol1e-6-warm",
                       "be-cholmod", "ida-klu-rtol1e-3", "ida-klu-rtol1e-5", "ida-krylov-rtol1e-3"}));
  EXPECT_EQ(default_steps(0.01), (std::vector<double>{0.001, 0.01}));
  EXPECT_EQ(default_steps(0.005), (std::vector<double>{0.001, 0.005}));
  EXPECT_EQ(default_steps(0.001), (std::vector<double>{0.001}));
  EXPECT_EQ(default_steps(0.0025), (std::vector<double>{0.0025}));  // 1 ms does not divide it
}

TEST(CompareSettings, WithIdaEveryRunIsPlannedAndTheReferenceIsIda) {
  std::string note;
  const std::vector<RunSpec> runs = plan_runs(default_settings(), scenario_with_step(0.01), tissue_like(true), note);
  ASSERT_EQ(runs.size(), 1u + 10u * 2u);
  EXPECT_TRUE(note.empty()) << note;
  EXPECT_TRUE(runs[0].is_reference);
  EXPECT_EQ(runs[0].step_s, 0.001);
  const SettingDescription reference = describe_setting(runs[0].parameters, tissue_like(true));
  EXPECT_EQ(reference.integrator, "ida");
  EXPECT_EQ(reference.linear_solver, "klu");
  EXPECT_EQ(reference.tolerance, 1e-7);
  for (const RunSpec& run : runs) EXPECT_TRUE(run.skipped.empty()) << run.setting << ": " << run.skipped;
  EXPECT_EQ(runs[1].setting, "be-pcgTwoLevel-tol1e-3-cap10");
  EXPECT_EQ(runs[1].step_s, 0.001);
  EXPECT_EQ(runs[2].step_s, 0.01);
  const SettingDescription lagged = describe_setting(runs[9].parameters, tissue_like(true));
  EXPECT_EQ(runs[9].setting, "be-pcgCholesky-tol1e-5-cap25");
  EXPECT_EQ(lagged.family(), "backwardEuler/pcgCholesky");
  EXPECT_EQ(lagged.tolerance, 1e-5);
  EXPECT_EQ(lagged.iteration_cap, 25);
  const SettingDescription warm = describe_setting(runs[11].parameters, tissue_like(true));
  EXPECT_EQ(runs[11].setting, "be-pcgTwoLevel-tol1e-6-warm");
  EXPECT_EQ(warm.family(), "backwardEuler/pcgTwoLevel");
  EXPECT_EQ(warm.tolerance, 1e-6);
  const SettingDescription cholmod = describe_setting(runs[13].parameters, tissue_like(true));
  EXPECT_EQ(runs[13].setting, "be-cholmod");
  EXPECT_EQ(cholmod.family(), "backwardEuler/cholmod");
  EXPECT_FALSE(cholmod.tolerance);
  EXPECT_FALSE(cholmod.iteration_cap);
}

TEST(CompareSettings, WithoutIdaTheIdaRowsAreSkippedAndTheReferenceFallsBack) {
  const ModelDescription old_tissue = tissue_like(false);
  std::string note;
  const std::vector<RunSpec> runs = plan_runs(default_settings(), scenario_with_step(0.01), old_tissue, note);
  ASSERT_EQ(runs.size(), 21u);
  EXPECT_NE(note.find("integrator.method"), std::string::npos) << note;
  EXPECT_EQ(describe_setting(runs[0].parameters, old_tissue).family(), "backwardEuler/cholmod");
  for (const RunSpec& run : runs) {
    const bool ida = run.setting.rfind("ida-", 0) == 0;
    EXPECT_EQ(run.skipped.empty(), !ida) << run.setting;
    if (ida) {
      EXPECT_NE(run.skipped.find("integrator.method"), std::string::npos) << run.skipped;
    } else {
      // Backward Euler needs no integrator.method on an FMU that only has backward Euler.
      for (const ParameterSetting& p : run.parameters) EXPECT_NE(p.name, "integrator.method");
    }
  }
  // The PCG defaults come from the FMU's start values.
  const SettingDescription pcg = describe_setting({}, old_tissue);
  EXPECT_EQ(pcg.tolerance, 0.001);
  EXPECT_EQ(pcg.iteration_cap, 10);
}

TEST(CompareSettings, ATableInAFileReplacesTheListAndIsCheckedAgainstTheFmu) {
  const TempDir dir;
  const std::filesystem::path file = dir.path() / "settings.toml";
  write_file(file, R"([compare]
steps = [0.002, 0.01]
[compare.reference]
step = 0.002
parameters = { "integrator.linearSolver" = "cholmod" }
[[compare.settings]]
name = "loose"
parameters = { "integrator.linearSolver" = "pcg", "integrator.pcgMaxIterations" = 5 }
[[compare.settings]]
name = "direct"
parameters = { "integrator.linearSolver" = 2 }
steps = [0.005]
)");
  const std::optional<CompareSettingsList> list = read_compare_table(file);
  ASSERT_TRUE(list);
  EXPECT_FALSE(list->built_in);
  std::string note;
  const std::vector<RunSpec> runs = plan_runs(*list, scenario_with_step(0.01), tissue_like(false), note);
  ASSERT_EQ(runs.size(), 1u + 2u + 1u);
  EXPECT_EQ(runs[0].step_s, 0.002);
  EXPECT_EQ(runs[3].setting, "direct");
  EXPECT_EQ(runs[3].step_s, 0.005);
  EXPECT_EQ(describe_setting(runs[3].parameters, tissue_like(false)).linear_solver, "cholmod");  // 2 = cholmod
  EXPECT_EQ(describe_setting(runs[1].parameters, tissue_like(false)).iteration_cap, 5);
}

// A setting's material model (issue 25): read from material.model (co-rotational when not set), in
// the row's family (the plot's series) only when it is Neo-Hookean, and kept by the CSV.
TEST(CompareSettings, TheMaterialModelIsPartOfTheSettingsFamily) {
  const std::vector<ParameterSetting> neo_hookean{{"material.model", std::string("stableNeoHookean")},
                                                  {"integrator.linearSolver", std::string("cholmod")}};
  const SettingDescription d = describe_setting(neo_hookean, tissue_like(true));
  EXPECT_EQ(d.material_model, "stableNeoHookean");
  EXPECT_EQ(d.family(), "backwardEuler/cholmod/stableNeoHookean");
  const SettingDescription plain =
      describe_setting({{"integrator.linearSolver", std::string("cholmod")}}, tissue_like(true));
  EXPECT_EQ(plain.material_model, "corotationalLinear");
  EXPECT_EQ(plain.family(), "backwardEuler/cholmod");
  CompareRow row;
  row.setting = "snh";
  row.integrator = "backwardEuler";
  row.linear_solver = "cholmod";
  row.material_model = "stableNeoHookean";
  row.internal_step_s = 0.01;
  const CompareRow back = parse_csv_row(csv_row(row));
  EXPECT_EQ(back.material_model, "stableNeoHookean");
  EXPECT_EQ(back.family(), "backwardEuler/cholmod/stableNeoHookean");
}

void expect_refused(const std::string& compare_table, const Scenario& scenario, const std::string& says) {
  const TempDir dir;
  const std::filesystem::path file = dir.path() / "settings.toml";
  write_file(file, compare_table);
  try {
    const std::optional<CompareSettingsList> list = read_compare_table(file);
    ASSERT_TRUE(list);
    std::string note;
    (void)plan_runs(*list, scenario, tissue_like(false), note);
    FAIL() << "accepted; expected a refusal saying " << says;
  } catch (const ScenarioError& error) {
    EXPECT_NE(std::string(error.what()).find(says), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find(file.string()), std::string::npos) << error.what();
  }
}

TEST(CompareSettings, MistakesAreRefusedNamingTheFileAndKey) {
  const Scenario scenario = scenario_with_step(0.01);
  expect_refused("[compare]\nsteps = [0.003]\n", scenario, "0.003 s does not divide the communication step 0.01 s");
  expect_refused("[compare]\nsteps = [-0.001]\n", scenario, "compare.steps");
  expect_refused("[compare]\nstep = [0.001]\n", scenario, "compare.step: unknown key");
  expect_refused("[[compare.settings]]\nname = \"x\"\nparameters = { \"integrator.pcgMaxIteration\" = 5 }\n", scenario,
                 "integrator.pcgMaxIteration: this Tissue.fmu has no variable of this name");
  expect_refused("[[compare.settings]]\nname = \"x\"\nparameters = { \"integrator.linearSolver\" = \"lu\" }\n",
                 scenario, "\"lu\" is not an item of LinearSolver");
  expect_refused("[[compare.settings]]\nname = \"x\"\nparameters = { \"contact.force\" = 1.0 }\n", scenario,
                 "not a parameter");
  expect_refused("[[compare.settings]]\nname = \"x\"\nparameters = { \"stepSize\" = 0.001 }\n", scenario, "stepSize");
  expect_refused("[[compare.settings]]\nname = \"x\"\n[[compare.settings]]\nname = \"x\"\n", scenario, "used twice");
  expect_refused("[[compare.settings]]\nname = \"x\"\nsteps = [0.004]\n", scenario, "does not divide");
  // A reference the FMU cannot run is refused when the user gave it (no silent fallback).
  expect_refused("[compare.reference]\nparameters = { \"integrator.method\" = \"ida\" }\n", scenario,
                 "compare.reference.parameters.integrator.method");
}

// --- plot and font ---

std::size_t count_pixels(const RgbImage& image, const Rgb& colour) {
  std::size_t n = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) n += image.pixel(x, y) == colour ? 1 : 0;
  }
  return n;
}

TEST(ComparePlot, DrawsSeriesFrontAndText) {
  LogLogPlot plot;
  plot.title = "title";
  plot.x_title = "cost";
  plot.y_title = "error";
  plot.series = {"a", "b"};
  plot.points = {{0.01, 1e-3, 0}, {0.1, 1e-5, 0}, {1.0, 1e-7, 1}, {2.0, 1e-4, 1}};
  plot.front = {0, 1, 2};
  plot.notes = {"a note"};
  const RgbImage image = render_log_log_plot(plot);
  EXPECT_EQ(image.width, 960);
  EXPECT_EQ(image.height, 640);
  EXPECT_GT(count_pixels(image, series_colour(0)), 2u * 60u);  // two discs of radius 5.5 and a legend disc
  EXPECT_GT(count_pixels(image, series_colour(1)), 2u * 60u);
  // The rings and the front's line are black, as are the frame and ticks.
  EXPECT_GT(count_pixels(image, Rgb{0, 0, 0}), 3u * 100u);
  // The title is drawn in the band above the plot area (anti-aliased: shades of its dark grey).
  const auto inked_rows = [](const RgbImage& picture, int from, int to) {
    std::size_t n = 0;
    for (int y = from; y < to; ++y) {
      for (int x = 0; x < picture.width; ++x) n += picture.pixel(x, y)[0] < 200 ? 1 : 0;
    }
    return n;
  };
  EXPECT_GT(inked_rows(image, 0, 45), 40u);
  LogLogPlot untitled = plot;
  untitled.title.clear();
  EXPECT_EQ(inked_rows(render_log_log_plot(untitled), 0, 45), 0u);
  // The same plot, the same pixels.
  EXPECT_EQ(render_log_log_plot(plot).rgb, image.rgb);

  plot.points.push_back({0.0, 1.0, 0});
  EXPECT_THROW((void)render_log_log_plot(plot), std::invalid_argument);
  plot.points.back() = {1.0, 1.0, 5};
  EXPECT_THROW((void)render_log_log_plot(plot), std::invalid_argument);
}

TEST(ComparePlot, OmittedRowsAreSaidInTheNotes) {
  CompareReport report;
  report.scenario = "s";
  report.reference = "ida/klu @ 1 ms";
  report.rows = {candidate("reference", 1e-3, 2.0, 0.0), candidate("twin", 1e-3, 1.0, 0.0),
                 candidate("shown", 1e-2, 0.1, 1e-5), candidate("broken", 1e-2, 0.1, 1e-5)};
  report.rows[3].rms_error_m.reset();
  std::vector<std::string> omitted;
  const LogLogPlot plot = compare_plot(report, omitted);
  ASSERT_EQ(plot.points.size(), 1u);
  ASSERT_EQ(omitted.size(), 2u);
  EXPECT_NE(omitted[0].find("zero error"), std::string::npos);
  EXPECT_NE(omitted[0].find("twin @ 1 ms"), std::string::npos) << omitted[0];
  EXPECT_NE(omitted[1].find("broken @ 10 ms"), std::string::npos) << omitted[1];
  EXPECT_EQ(plot.width, COMPARE_PLOT_WIDTH);
  EXPECT_EQ(plot.height, COMPARE_PLOT_HEIGHT);
}

// compare.json holds what the report holds: a metric that is not finite (a run that blew up, a
// cost that could not be measured) is null, text keeps its quotes. Before nlohmann::json wrote it,
// a NaN came out as the bare word nan and the file did not parse.
TEST(CompareReportJson, ParsesBackWithNullForWhatIsNotFinite) {
  CompareReport report;
  report.scenario = "beam \"two\" cuts";
  report.reference = "ida/klu @ 1 ms";
  const double inf = std::numeric_limits<double>::infinity();
  report.rows = {candidate("reference", 1e-3, 2.0, 0.0), candidate("fast", 1e-3, 0.1, 1e-5),
                 candidate("blew up", 1e-2, inf, std::numeric_limits<double>::quiet_NaN()),
                 candidate("unmeasured", 1e-2, inf, 1e-4)};
  report.rows[1].tolerance = 1e-3;
  report.notes = {"a note"};
  const test::TempDir dir;
  write_compare_outputs(dir.path(), report);
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir.path() / "compare.json"));
  EXPECT_EQ(j["scenario"].get<std::string>(), report.scenario);
  ASSERT_EQ(j["rows"].size(), 4u);
  EXPECT_EQ(j["rows"][1]["tolerance"].get<double>(), 1e-3);
  EXPECT_EQ(j["rows"][1]["rms_error_m"].get<double>(), 1e-5);
  EXPECT_TRUE(j["rows"][0]["tolerance"].is_null());  // not set
  EXPECT_TRUE(j["rows"][2]["rms_error_m"].is_null());
  EXPECT_TRUE(j["rows"][2]["cpu_s_per_sim_s"].is_null());
  EXPECT_EQ(j["notes"][0].get<std::string>(), "a note");
  EXPECT_TRUE(j["recommendations"].is_array());
  // The plot leaves the rows without a finite error and cost out and says so (an infinite cost
  // used to reach the plotter, which refused it, and nothing was written).
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "compare.png"));
  std::vector<std::string> omitted;
  (void)compare_plot(report, omitted);
  ASSERT_EQ(omitted.size(), 2u);
  EXPECT_NE(omitted[1].find("blew up @ 10 ms, unmeasured @ 10 ms"), std::string::npos) << omitted[1];
}

}  // namespace
}  // namespace tissue::host
