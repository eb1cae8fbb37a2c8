// render_log_log_plot (see plot_png.hpp): a small raster canvas (pixels, discs, rings, thick
// lines, text in the 5 x 7 font, also turned upwards) and the plot's layout on it.
#include "compare/plot_png.hpp"

#include "compare/bitmap_font.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tissue::host {
namespace {

constexpr Rgb BLACK{0, 0, 0};
constexpr Rgb WHITE{255, 255, 255};
constexpr Rgb GRID{222, 222, 226};
constexpr Rgb TEXT{30, 30, 35};

class Canvas {
 public:
  Canvas(int width, int height) {
    m_image.width = width;
    m_image.height = height;
    m_image.rgb.assign(static_cast<std::size_t>(3 * width * height), 255);
  }

  void put(int x, int y, const Rgb& c) {
    if (x < 0 || y < 0 || x >= m_image.width || y >= m_image.height) return;
    const auto at = static_cast<std::size_t>(3 * (y * m_image.width + x));
    std::copy(c.begin(), c.end(), m_image.rgb.begin() + static_cast<std::ptrdiff_t>(at));
  }
  void fill_rect(int x0, int y0, int x1, int y1, const Rgb& c) {
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) put(x, y, c);
    }
  }
  void hline(int x0, int x1, int y, const Rgb& c) { fill_rect(std::min(x0, x1), y, std::max(x0, x1), y, c); }
  void vline(int x, int y0, int y1, const Rgb& c) { fill_rect(x, std::min(y0, y1), x, std::max(y0, y1), c); }

  /// Pixels whose centres are within r of (cx, cy); with inner > 0 a ring from inner to r.
  void disc(double cx, double cy, double r, const Rgb& c, double inner = -1.0) {
    for (int y = static_cast<int>(std::floor(cy - r)); y <= static_cast<int>(std::ceil(cy + r)); ++y) {
      for (int x = static_cast<int>(std::floor(cx - r)); x <= static_cast<int>(std::ceil(cx + r)); ++x) {
        const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
        if (d <= r && d > inner) put(x, y, c);
      }
    }
  }
  /// A line of the given width: discs stamped every half pixel.
  void line(double x0, double y0, double x1, double y1, double width, const Rgb& c) {
    const double length = std::hypot(x1 - x0, y1 - y0);
    const int steps = std::max(1, static_cast<int>(std::ceil(length * 2.0)));
    for (int k = 0; k <= steps; ++k) {
      const double t = static_cast<double>(k) / steps;
      disc(x0 + t * (x1 - x0), y0 + t * (y1 - y0), width / 2.0, c);
    }
  }

  static int text_width(const std::string& text, int scale) {
    return text.empty() ? 0 : static_cast<int>(text.size()) * (GLYPH_WIDTH + 1) * scale - scale;
  }
  static int text_height(int scale) { return GLYPH_HEIGHT * scale; }
  /// Height of capitals and digits (the rows above the baseline).
  static int cap_height(int scale) { return 7 * scale; }
  /// Text with its top-left corner at (x, y).
  void text(int x, int y, const std::string& text, int scale, const Rgb& c) {
    for (std::size_t i = 0; i < text.size(); ++i) {
      const auto& rows = glyph(text[i]);
      const int left = x + static_cast<int>(i) * (GLYPH_WIDTH + 1) * scale;
      for (int row = 0; row < GLYPH_HEIGHT; ++row) {
        for (int column = 0; column < GLYPH_WIDTH; ++column) {
          if ((rows[static_cast<std::size_t>(row)] >> (GLYPH_WIDTH - 1 - column) & 1U) == 0) continue;
          fill_rect(left + column * scale, y + row * scale, left + (column + 1) * scale - 1, y + (row + 1) * scale - 1,
                    c);
        }
      }
    }
  }
  /// Text turned a quarter turn anticlockwise (read upwards), its bottom-left corner at (x, y).
  void text_up(int x, int y, const std::string& text, int scale, const Rgb& c) {
    for (std::size_t i = 0; i < text.size(); ++i) {
      const auto& rows = glyph(text[i]);
      const int bottom = y - static_cast<int>(i) * (GLYPH_WIDTH + 1) * scale;
      for (int row = 0; row < GLYPH_HEIGHT; ++row) {
        for (int column = 0; column < GLYPH_WIDTH; ++column) {
          if ((rows[static_cast<std::size_t>(row)] >> (GLYPH_WIDTH - 1 - column) & 1U) == 0) continue;
          // Glyph column -> up the image, glyph row -> right.
          fill_rect(x + row * scale, bottom - (column + 1) * scale + 1, x + (row + 1) * scale - 1,
                    bottom - column * scale, c);
        }
      }
    }
  }

  RgbImage take() { return std::move(m_image); }

 private:
  RgbImage m_image;
};

/// A decade's label: plain for 0.01 .. 1000, else "1e-5".
std::string decade_label(int exponent) {
  std::string label;  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on operator+ chains
  if (exponent >= 0 && exponent <= 3) {
    label.append("1").append(static_cast<std::size_t>(exponent), '0');
  } else if (exponent < 0 && exponent >= -2) {
    label.append("0.").append(static_cast<std::size_t>(-exponent - 1), '0').append("1");
  } else {
    label.append("1e").append(std::to_string(exponent));
  }
  return label;
}

/// Decades covering [lo, hi] (log10 values), at least one.
struct Decades {
  int first = 0, last = 1;
  double from = 0.0, to = 1.0;  ///< the mapped log range, a little wider than the decades' span
};

Decades decades(double lo, double hi) {
  Decades d;
  d.first = static_cast<int>(std::floor(lo));
  d.last = static_cast<int>(std::ceil(hi));
  if (d.last == d.first) ++d.last;
  const double pad = 0.03 * (d.last - d.first);
  d.from = d.first - pad;
  d.to = d.last + pad;
  return d;
}

}  // namespace

Rgb series_colour(std::size_t k) {
  // Tableau 10: distinct, and readable on white.
  static constexpr std::array<Rgb, 10> PALETTE{{{31, 119, 180},
                                                {255, 127, 14},
                                                {44, 160, 44},
                                                {214, 39, 40},
                                                {148, 103, 189},
                                                {140, 86, 75},
                                                {227, 119, 194},
                                                {127, 127, 127},
                                                {188, 189, 34},
                                                {23, 190, 207}}};
  return PALETTE[k % PALETTE.size()];
}

namespace {

constexpr int BIG = 2;  // scale of the title, tick labels, axis titles and legend (notes: 1)

// The plot area on the canvas, in pixels, and the log-log mapping into it.
struct PlotFrame {
  int left = 110, top = 50, right = 0, bottom = 0;
  Decades xd, yd;

  [[nodiscard]] double px(double x) const {
    return left + (std::log10(x) - xd.from) / (xd.to - xd.from) * (right - left);
  }
  [[nodiscard]] double py(double y) const {
    return bottom - (std::log10(y) - yd.from) / (yd.to - yd.from) * (bottom - top);
  }
  [[nodiscard]] int decade_x(int e) const { return static_cast<int>(std::lround(px(std::pow(10.0, e)))); }
  [[nodiscard]] int decade_y(int e) const { return static_cast<int>(std::lround(py(std::pow(10.0, e)))); }
};

// The decades the two axes span; refuses points that are not positive and finite, and bad indices.
std::array<Decades, 2> axis_decades(const LogLogPlot& plot) {
  double x_lo = 0.0, x_hi = 1.0, y_lo = 0.0, y_hi = 1.0;
  for (std::size_t i = 0; i < plot.points.size(); ++i) {
    const PlotPoint& p = plot.points[i];
    if (!(p.x > 0.0) || !(p.y > 0.0) || !std::isfinite(p.x) || !std::isfinite(p.y)) {
      throw std::invalid_argument("render_log_log_plot: point " + std::to_string(i) + " is not positive and finite");
    }
    if (p.series >= plot.series.size()) throw std::invalid_argument("render_log_log_plot: series out of range");
    const double lx = std::log10(p.x), ly = std::log10(p.y);
    x_lo = i == 0 ? lx : std::min(x_lo, lx);
    x_hi = i == 0 ? lx : std::max(x_hi, lx);
    y_lo = i == 0 ? ly : std::min(y_lo, ly);
    y_hi = i == 0 ? ly : std::max(y_hi, ly);
  }
  for (const std::size_t f : plot.front) {
    if (f >= plot.points.size()) throw std::invalid_argument("render_log_log_plot: front index out of range");
  }
  // Without points the axes span one decade (1 to 10) each, so that the frame still draws.
  return {decades(x_lo, x_hi), decades(y_lo, y_hi)};
}

// Layout: title on top, legend on the right, tick labels and titles left and below, notes last.
PlotFrame plot_frame(const LogLogPlot& plot, int note_line) {
  const std::array<Decades, 2> axes = axis_decades(plot);
  int legend_width = Canvas::text_width(plot.front_name, BIG);
  for (const std::string& name : plot.series) legend_width = std::max(legend_width, Canvas::text_width(name, BIG));
  legend_width = std::min(legend_width + 36, plot.width / 3);
  const int notes_height = static_cast<int>(plot.notes.size()) * note_line;
  PlotFrame frame;
  frame.right = plot.width - legend_width - 30;
  frame.bottom = plot.height - 78 - notes_height;
  if (frame.right - frame.left < 100 || frame.bottom - frame.top < 100) {
    throw std::invalid_argument("render_log_log_plot: too small");
  }
  frame.xd = axes[0];
  frame.yd = axes[1];
  return frame;
}

// Grid, ticks and their labels (thinned to about ten per axis), the frame and the axis titles.
void draw_axes(Canvas& canvas, const PlotFrame& f, const LogLogPlot& plot) {
  const int x_every = std::max(1, (f.xd.last - f.xd.first + 9) / 10);
  const int y_every = std::max(1, (f.yd.last - f.yd.first + 9) / 10);
  for (int e = f.xd.first; e <= f.xd.last; ++e) {
    const int x = f.decade_x(e);
    canvas.vline(x, f.top, f.bottom, GRID);
    canvas.vline(x, f.bottom - 6, f.bottom, BLACK);
    if ((e - f.xd.first) % x_every == 0) {
      const std::string label = decade_label(e);
      canvas.text(x - Canvas::text_width(label, BIG) / 2, f.bottom + 8, label, BIG, TEXT);
    }
    for (int m = 2; m <= 9 && e < f.xd.last && f.xd.last - f.xd.first <= 8; ++m) {
      canvas.vline(static_cast<int>(std::lround(f.px(m * std::pow(10.0, e)))), f.bottom - 3, f.bottom, BLACK);
    }
  }
  for (int e = f.yd.first; e <= f.yd.last; ++e) {
    const int y = f.decade_y(e);
    canvas.hline(f.left, f.right, y, GRID);
    canvas.hline(f.left, f.left + 6, y, BLACK);
    if ((e - f.yd.first) % y_every == 0) {
      const std::string label = decade_label(e);
      canvas.text(f.left - 8 - Canvas::text_width(label, BIG), y - Canvas::cap_height(BIG) / 2, label, BIG, TEXT);
    }
    for (int m = 2; m <= 9 && e < f.yd.last && f.yd.last - f.yd.first <= 8; ++m) {
      canvas.hline(f.left, f.left + 3, static_cast<int>(std::lround(f.py(m * std::pow(10.0, e)))), BLACK);
    }
  }
  canvas.hline(f.left, f.right, f.top, BLACK);
  canvas.hline(f.left, f.right, f.bottom, BLACK);
  canvas.vline(f.left, f.top, f.bottom, BLACK);
  canvas.vline(f.right, f.top, f.bottom, BLACK);
  canvas.text((f.left + f.right - Canvas::text_width(plot.x_title, BIG)) / 2, f.bottom + 36, plot.x_title, BIG, TEXT);
  canvas.text_up(16, (f.top + f.bottom + Canvas::text_width(plot.y_title, BIG)) / 2, plot.y_title, BIG, TEXT);
}

// The front behind the points, then the points, then the rings.
void draw_points(Canvas& canvas, const PlotFrame& f, const LogLogPlot& plot) {
  std::vector<std::size_t> front = plot.front;
  std::sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) {
    return plot.points[a].x < plot.points[b].x ||
           (plot.points[a].x == plot.points[b].x && plot.points[a].y > plot.points[b].y);
  });
  for (std::size_t k = 1; k < front.size(); ++k) {
    const PlotPoint& a = plot.points[front[k - 1]];
    const PlotPoint& b = plot.points[front[k]];
    canvas.line(f.px(a.x), f.py(a.y), f.px(b.x), f.py(b.y), 2.0, BLACK);
  }
  for (const PlotPoint& p : plot.points) canvas.disc(f.px(p.x), f.py(p.y), 5.5, series_colour(p.series));
  for (const std::size_t k : front) canvas.disc(f.px(plot.points[k].x), f.py(plot.points[k].y), 10.0, BLACK, 7.5);
}

// One line per series, then the front's, right of the plot area.
void draw_legend(Canvas& canvas, const PlotFrame& f, const LogLogPlot& plot) {
  const int line_height = Canvas::text_height(BIG) + 8;
  const int legend_x = f.right + 20;
  int legend_y = f.top + 4;
  for (std::size_t k = 0; k < plot.series.size(); ++k, legend_y += line_height) {
    canvas.disc(legend_x + 10, legend_y + Canvas::cap_height(BIG) / 2, 5.5, series_colour(k));
    canvas.text(legend_x + 26, legend_y, plot.series[k], BIG, TEXT);
  }
  if (!plot.front.empty()) {
    const int middle = legend_y + Canvas::cap_height(BIG) / 2;
    canvas.line(legend_x, middle, legend_x + 20, middle, 2.0, BLACK);
    canvas.disc(legend_x + 10, middle, 10.0, BLACK, 7.5);
    canvas.text(legend_x + 26, legend_y, plot.front_name, BIG, TEXT);
  }
}

}  // namespace

RgbImage render_log_log_plot(const LogLogPlot& plot) {
  if (plot.width < 320 || plot.height < 240 || plot.width > 8192 || plot.height > 8192) {
    throw std::invalid_argument("render_log_log_plot: size must be 320 x 240 to 8192 x 8192");
  }
  const int note_line = Canvas::text_height(1) + 3;
  const PlotFrame frame = plot_frame(plot, note_line);
  Canvas canvas(plot.width, plot.height);
  canvas.fill_rect(0, 0, plot.width - 1, plot.height - 1, WHITE);
  canvas.text((plot.width - Canvas::text_width(plot.title, BIG)) / 2, 14, plot.title, BIG, TEXT);
  draw_axes(canvas, frame, plot);
  draw_points(canvas, frame, plot);
  draw_legend(canvas, frame, plot);
  int note_y = frame.bottom + 62;
  for (const std::string& note : plot.notes) {
    canvas.text(12, note_y, note, 1, TEXT);
    note_y += note_line;
  }
  return canvas.take();
}

}  // namespace tissue::host
