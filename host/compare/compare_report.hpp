// What tissue-host compare writes once every row is in (rank 0): compare.csv, compare.png (error
// against cost, log-log, coloured by integrator family, Pareto front ringed and joined),
// recommendation.txt and compare.json, and the lines it prints.
#pragma once

#include "compare/compare_table.hpp"
#include "compare/plot_png.hpp"
#include "compare/recommendation.hpp"

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace tissue::host {

/// compare.png's size in pixels.
inline constexpr int COMPARE_PLOT_WIDTH = 960;
inline constexpr int COMPARE_PLOT_HEIGHT = 720;

/// Everything a comparison found.
struct CompareReport {
  std::string scenario;
  std::string reference;           ///< how the reference was run, e.g. "ida/klu, rtol 1e-07 @ 1 ms"
  std::vector<std::string> notes;  ///< the reference's fallback, rows not plotted
  std::vector<CompareRow> rows;    ///< reference first
  std::vector<Recommendation> recommendations;
  int processes = 1;  ///< MPI ranks the runs were dealt over
  int threads = 1;    ///< threads per process (--jobs)
};

/// Marks the Pareto front (comparable rows but the reference) in `rows`.
void mark_pareto_front(std::vector<CompareRow>& rows);

/// The error-against-cost plot of the rows; the rows it leaves out (zero error on a log axis, no
/// error or no cost) are said in `omitted` (one line each) and in the plot's notes.
[[nodiscard]] LogLogPlot compare_plot(const CompareReport& report, std::vector<std::string>& omitted);

/// Writes compare.csv, compare.png, recommendation.txt and compare.json into `dir` (created).
void write_compare_outputs(const std::filesystem::path& dir, const CompareReport& report);

/// The report in a few lines: the table, the recommendations, where the files are.
void print_compare(std::ostream& out, const CompareReport& report, const std::filesystem::path& dir);

}  // namespace tissue::host
