// tissue-host compare on the built FMUs (the beam let go under gravity, tests/host/compare/):
// * the default list gives one row per (setting, step) with every column, the reference row has
//   zero error, and the numbers say what the integrators are: backward Euler converges as its
//   step shrinks, a PCG capped at 10 iterations is further off than CHOLMOD at the same step, a
//   converged PCG agrees with CHOLMOD, a tighter IDA tolerance is closer to the reference; the
//   PNG decodes at its size, the recommendations name the three uses;
// * runs on two threads give the same errors, bit for bit, as on one; and so do two MPI ranks;
// * mistakes (a misspelt parameter, a step that does not divide the communication step, --jobs 0)
//   end tissue-host with a message and exit code 2, before anything runs.
#include "compare/compare.hpp"
#include "host_test_support.hpp"

#include <png.h>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

namespace tissue::host {
namespace {

using test::TempDir;

const std::filesystem::path SCENARIOS = TISSUE_COMPARE_TEST_DIR;
const std::filesystem::path FMUS = TISSUE_FMU_DIR;
const std::filesystem::path TISSUE_HOST = TISSUE_HOST_EXECUTABLE;

const std::vector<std::string> COLUMNS{"setting",     "integrator",    "linear_solver",   "material_model",
                                       "tolerance",   "iteration_cap", "internal_step_s", "cpu_s_per_sim_s",
                                       "rms_error_m", "max_error_m",   "force_error_n",   "energy_drift_j",
                                       "iterations",  "failures",      "pareto",          "note"};
// The columns that must not depend on threads or processes (CPU time does).
const std::vector<std::string> REPRODUCIBLE{"setting",       "internal_step_s", "rms_error_m", "max_error_m",
                                            "force_error_n", "energy_drift_j",  "iterations",  "failures"};

using CsvRow = std::map<std::string, std::string>;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (const char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

std::vector<CsvRow> read_csv(const std::filesystem::path& file, std::vector<std::string>* header = nullptr) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> names = split(line);
  if (header != nullptr) *header = names;
  std::vector<CsvRow> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> fields = split(line);
    CsvRow row;
    for (std::size_t k = 0; k < names.size() && k < fields.size(); ++k) row[names[k]] = fields[k];
    rows.push_back(row);
  }
  return rows;
}

const CsvRow& row_of(const std::vector<CsvRow>& rows, const std::string& setting, const std::string& step_s) {
  for (const CsvRow& row : rows) {
    if (row.at("setting") == setting && std::stod(row.at("internal_step_s")) == std::stod(step_s)) return row;
  }
  throw std::runtime_error("no row " + setting + " @ " + step_s);
}

double number(const CsvRow& row, const std::string& column) {
  const std::string& text = row.at(column);
  if (text.empty()) throw std::runtime_error(row.at("setting") + ": no " + column + " (" + row.at("note") + ")");
  return std::stod(text);
}

void expect_same_reproducible_columns(const std::filesystem::path& a, const std::filesystem::path& b) {
  const std::vector<CsvRow> first = read_csv(a), second = read_csv(b);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    for (const std::string& column : REPRODUCIBLE) {
      EXPECT_EQ(first[i].at(column), second[i].at(column)) << "row " << i << " " << column;
    }
  }
}

struct Decoded {
  int width = 0, height = 0;
};

Decoded decode_png_size(const std::filesystem::path& file) {
  const std::string bytes = test::read_file(file);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()) == 0) return {};
  png.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> pixels(PNG_IMAGE_SIZE(png));
  if (png_image_finish_read(&png, nullptr, pixels.data(), 0, nullptr) == 0) return {};
  return {static_cast<int>(png.width), static_cast<int>(png.height)};
}

struct Command {
  int exit_code = -1;
  std::string output;
};

Command run_command(const std::string& command) {
  Command result;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe) != nullptr) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// Appended piecewise: GCC 12 warns falsely (-Wrestrict) on operator+ chains.
std::string quoted(const std::filesystem::path& path) { return std::string("'").append(path.string()).append("'"); }

CompareOptions options_for(const std::filesystem::path& output, int jobs, bool small) {
  CompareOptions options;
  options.scenario_file = SCENARIOS / "beam_sag.toml";
  if (small) options.settings_file = SCENARIOS / "small_settings.toml";
  options.output_dir = output;
  options.fmu_dir = FMUS;
  options.jobs = jobs;
  return options;
}

TEST(CompareRuns, TheDefaultListOnTheBeam) {
  const TempDir dir;
  SingleProcess one;
  CompareOptions options = options_for(dir.path(), 2, false);
  // IDA with GMRES is the slow one: keep the sweep to seconds (under AddressSanitizer, ~10x slower,
  // two communication steps instead of five).
#if defined(__SANITIZE_ADDRESS__)
  options.duration_s = 0.02;
#else
  options.duration_s = 0.05;
#endif
  const CompareReport report = run_compare(options, one);
  std::vector<std::string> header;
  const std::vector<CsvRow> rows = read_csv(dir.path() / "compare.csv", &header);
  EXPECT_EQ(header, COLUMNS);
  ASSERT_EQ(rows.size(), 1u + 10u * 2u);
  EXPECT_EQ(report.rows.size(), rows.size());
  EXPECT_EQ(rows[0].at("setting"), "reference");
  for (const char* column : {"rms_error_m", "max_error_m", "force_error_n", "energy_drift_j"}) {
    EXPECT_EQ(number(rows[0], column), 0.0) << column;
  }
  EXPECT_EQ(rows[0].at("pareto"), "0");
  const std::vector<std::string> settings{"be-pcgTwoLevel-tol1e-3-cap10",
                                          "be-pcgTwoLevel-tol1e-3-cap10-atStart",
                                          "be-pcg-tol1e-3-cap10",
                                          "be-pcg-tol1e-6-cap1000",
                                          "be-pcgCholesky-tol1e-5-cap25",
                                          "be-pcgTwoLevel-tol1e-6-warm",
                                          "be-cholmod",
                                          "ida-klu-rtol1e-3",
                                          "ida-klu-rtol1e-5",
                                          "ida-krylov-rtol1e-3"};
  int on_front = 0;
  for (std::size_t k = 0; k < settings.size(); ++k) {
    for (std::size_t s = 0; s < 2; ++s) {
      const CsvRow& row = rows[1 + 2 * k + s];
      EXPECT_EQ(row.at("setting"), settings[k]);
      EXPECT_EQ(std::stod(row.at("internal_step_s")), s == 0 ? 0.001 : 0.01);
      if (row.at("failures") != "0" && settings[k] == "ida-krylov-rtol1e-3") {
        // GMRES crawls through the 10 ms steps of the released beam (micro-second internal steps):
        // IDA's runaway guard refuses them, and the row says so (docs/BENCHMARKS.md, extremes).
        EXPECT_NE(row.at("note").find("max_internal_steps"), std::string::npos) << row.at("note");
        continue;
      }
      EXPECT_EQ(row.at("failures"), "0") << row.at("setting") << ": " << row.at("note");
      EXPECT_GT(number(row, "cpu_s_per_sim_s"), 0.0);
      EXPECT_GT(number(row, "rms_error_m"), 0.0) << row.at("setting");
      EXPECT_GE(number(row, "max_error_m"), number(row, "rms_error_m"));
      EXPECT_FALSE(row.at("iterations").empty());
      on_front += row.at("pareto") == "1" ? 1 : 0;
    }
  }
  EXPECT_GE(on_front, 2);
  EXPECT_EQ(rows[1].at("integrator"), "backwardEuler");
  EXPECT_EQ(rows[1].at("linear_solver"), "pcgTwoLevel");
  EXPECT_EQ(rows[1].at("iteration_cap"), "10");
  EXPECT_EQ(std::stod(rows[1].at("tolerance")), 1e-3);
  EXPECT_EQ(rows[9].at("linear_solver"), "pcgCholesky");
  EXPECT_EQ(rows[15].at("integrator"), "ida");
  EXPECT_EQ(rows[15].at("linear_solver"), "klu");

  const auto rms = [&](const std::string& setting, const std::string& step) {
    return number(row_of(rows, setting, step), "rms_error_m");
  };
  // Backward Euler is first order: a tenth of the step, a good deal less error.
  EXPECT_LT(rms("be-cholmod", "0.001"), 0.5 * rms("be-cholmod", "0.01"));
  // Ten PCG iterations do not solve the 10 ms step: further off than the exact solve.
  EXPECT_GT(rms("be-pcg-tol1e-3-cap10", "0.01"), 1.5 * rms("be-cholmod", "0.01"));
  // The default's ten two-level iterations do (issue 40): the slow motions converge.
  std::printf("rms error at 10 ms: two-level %.4g m, Jacobi %.4g m, CHOLMOD %.4g m\n",
              rms("be-pcgTwoLevel-tol1e-3-cap10", "0.01"), rms("be-pcg-tol1e-3-cap10", "0.01"), rms("be-cholmod", "0.01"));
  EXPECT_NEAR(rms("be-pcgTwoLevel-tol1e-3-cap10", "0.01"), rms("be-cholmod", "0.01"), 0.05 * rms("be-cholmod", "0.01"));
  // A converged PCG solves the same equations as CHOLMOD; so does CG on the lagged factor at 1e-5.
  EXPECT_NEAR(rms("be-pcg-tol1e-6-cap1000", "0.001"), rms("be-cholmod", "0.001"), 1e-3 * rms("be-cholmod", "0.001"));
  EXPECT_NEAR(rms("be-pcgCholesky-tol1e-5-cap25", "0.01"), rms("be-cholmod", "0.01"), 1e-3 * rms("be-cholmod", "0.01"));
  // The converged two-level step from the Galerkin warm start solves them too, at both steps.
  EXPECT_NEAR(rms("be-pcgTwoLevel-tol1e-6-warm", "0.01"), rms("be-cholmod", "0.01"), 1e-3 * rms("be-cholmod", "0.01"));
  EXPECT_NEAR(rms("be-pcgTwoLevel-tol1e-6-warm", "0.001"), rms("be-cholmod", "0.001"), 1e-3 * rms("be-cholmod", "0.001"));
  // IDA's error control: a tighter tolerance is closer to the (tighter still) reference.
  EXPECT_LT(rms("ida-klu-rtol1e-5", "0.001"), 0.1 * rms("ida-klu-rtol1e-3", "0.001"));

  const Decoded png = decode_png_size(dir.path() / "compare.png");
  EXPECT_EQ(png.width, COMPARE_PLOT_WIDTH);
  EXPECT_EQ(png.height, COMPARE_PLOT_HEIGHT);
  const std::string recommendation = test::read_file(dir.path() / "recommendation.txt");
  for (const std::string use : {"1 kHz haptic: ", "100 Hz visual: ", "offline accuracy: "}) {
    EXPECT_NE(recommendation.find(use), std::string::npos) << recommendation;
  }
  ASSERT_EQ(report.recommendations.size(), 3u);
  ASSERT_TRUE(report.recommendations[2].row);  // something is always the most accurate
  EXPECT_NE(test::read_file(dir.path() / "compare.json").find("\"recommendations\""), std::string::npos);
}

TEST(CompareRuns, TwoThreadsGiveTheSameErrorsAsOne) {
  const TempDir one_thread, two_threads;
  SingleProcess one;
  (void)run_compare(options_for(one_thread.path(), 1, true), one);
  (void)run_compare(options_for(two_threads.path(), 2, true), one);
  const std::vector<CsvRow> rows = read_csv(one_thread.path() / "compare.csv");
  ASSERT_EQ(rows.size(), 1u + 2u * 2u + 1u);
  expect_same_reproducible_columns(one_thread.path() / "compare.csv", two_threads.path() / "compare.csv");
}

TEST(CompareRuns, TwoMpiRanksWriteOneCsvWithTheSameErrors) {
#ifndef TISSUE_HOST_HAS_MPI
  GTEST_SKIP() << "tissue-host was built without MPI";
#else
  const std::filesystem::path mpirun = TISSUE_MPIEXEC;
  if (mpirun.empty() || !std::filesystem::exists(mpirun)) GTEST_SKIP() << "no mpirun (apt-get install openmpi-bin)";
  const TempDir single, ranks;
  const std::string common = quoted(SCENARIOS / "beam_sag.toml") + " --settings " +
                             quoted(SCENARIOS / "small_settings.toml") + " --fmu-dir " + quoted(FMUS) + " -q";
  const Command alone =
      run_command(quoted(TISSUE_HOST) + " compare " + common + " --jobs 1 -o " + quoted(single.path()));
  ASSERT_EQ(alone.exit_code, 0) << alone.output;
  // As root Open MPI wants to be told; --oversubscribe: two ranks on any machine. In the asan build
  // no leak check under mpirun: Open MPI leaves allocations at exit in plugins it has unloaded (so
  // no suppression can name them); the run above checks ours.
  const Command mpi = run_command(
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
      "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 " +
      quoted(mpirun) + " --oversubscribe -n 2 " + quoted(TISSUE_HOST) + " compare " + common + " -o " +
      quoted(ranks.path()));
  ASSERT_EQ(mpi.exit_code, 0) << mpi.output;
  EXPECT_NE(mpi.output.find("on 2 processes"), std::string::npos) << mpi.output;
  // Rank 0 alone prints and writes: one table.
  EXPECT_EQ(mpi.output.find("compare beam-sag"), mpi.output.rfind("compare beam-sag")) << mpi.output;
  expect_same_reproducible_columns(single.path() / "compare.csv", ranks.path() / "compare.csv");
#endif
}

void expect_refused(const std::string& arguments, const std::string& says) {
  const TempDir dir;
  const Command result =
      run_command(quoted(TISSUE_HOST) + " compare " + quoted(SCENARIOS / "beam_sag.toml") + " --fmu-dir " +
                  quoted(FMUS) + " -q -o " + quoted(dir.path() / "out") + " " + arguments);
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find(says), std::string::npos) << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "compare.csv"));
}

TEST(CompareRuns, MistakesEndWithAMessageAndExitCode2) {
  expect_refused("--settings " + quoted(SCENARIOS / "unknown_parameter.toml"),
                 "integrator.pcgMaxIteration: this Tissue.fmu has no variable of this name");
  expect_refused("--steps 0.003", "0.003 s does not divide the communication step 0.01 s");
  expect_refused("--jobs 0", "--jobs must be at least 1, got 0");
}

}  // namespace
}  // namespace tissue::host
