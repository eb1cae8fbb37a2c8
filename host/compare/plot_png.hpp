// A log-log scatter plot drawn into an RgbImage (host/output writes it as PNG) with cairo: points
// coloured by series with a legend, a highlighted subset ringed and joined by a line (the Pareto
// front), decade grid lines with labelled ticks ("1e-3"), minor ticks, axis titles and a title, in
// DejaVu Sans, anti-aliased. Deterministic: the same plot gives the same pixels on one machine.
#pragma once

#include "output/png_renderer.hpp"

#include <cstddef>
#include <string>
#include <vector>

namespace tissue::host {

struct PlotPoint {
  double x = 1.0, y = 1.0;  ///< both > 0
  std::size_t series = 0;   ///< index into LogLogPlot::series
};

struct LogLogPlot {
  int width = 960, height = 640;  ///< pixels, at least 320 x 240
  std::string title, x_title, y_title;
  std::vector<std::string> series;  ///< legend entries; colours from a fixed palette in this order
  std::vector<PlotPoint> points;    ///< may be empty (then both axes span 1 to 10)
  std::vector<std::size_t> front;   ///< points ringed and joined (in increasing x)
  std::string front_name = "Pareto front";
  std::vector<std::string> notes;  ///< lines under the plot
};

/// How many characters of a note fit on one line of a plot `width` pixels wide (the notes' font
/// with room to spare; the caller wraps longer notes).
[[nodiscard]] std::size_t note_characters(int width);

/// The palette colour of series k (cycles after ten).
[[nodiscard]] Rgb series_colour(std::size_t k);

/// Draws the plot; throws std::invalid_argument for a point that is not positive and finite, a
/// series index out of range, a front index out of range, or a size outside 320 x 240 to 8192 x 8192,
/// std::runtime_error when cairo cannot make the image.
[[nodiscard]] RgbImage render_log_log_plot(const LogLogPlot& plot);

}  // namespace tissue::host
