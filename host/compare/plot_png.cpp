// render_log_log_plot (see plot_png.hpp), drawn with cairo: anti-aliased discs, rings and lines,
// and text in DejaVu Sans (measured, so that the layout fits the labels it has).
#include "compare/plot_png.hpp"

#include <cairo.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace tissue::host {
namespace {

constexpr Rgb BLACK{0, 0, 0};
constexpr Rgb WHITE{255, 255, 255};
constexpr Rgb GRID{222, 222, 226};
constexpr Rgb TEXT{30, 30, 35};

// Font sizes in pixels.
constexpr double TITLE_SIZE = 18.0;
constexpr double LABEL_SIZE = 14.0;  // tick labels, axis titles, legend
constexpr double NOTE_SIZE = 12.0;
constexpr double NOTE_LINE = 16.0;
constexpr double POINT_RADIUS = 5.5;
constexpr double RING_RADIUS = 8.75, RING_WIDTH = 2.5;  // the front's rings

// A cairo image surface and its context, freed together.
class Drawing {
 public:
  Drawing(int width, int height)
      : m_surface(cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height), cairo_surface_destroy),
        m_cr(cairo_create(m_surface.get()), cairo_destroy) {
    if (cairo_surface_status(m_surface.get()) != CAIRO_STATUS_SUCCESS || cairo_status(m_cr.get()) != CAIRO_STATUS_SUCCESS) {
      throw std::runtime_error("render_log_log_plot: cairo could not make a " + std::to_string(width) + " x " +
                               std::to_string(height) + " image");
    }
    cairo_select_font_face(m_cr.get(), "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  }
  [[nodiscard]] cairo_t* cr() const { return m_cr.get(); }

  void colour(const Rgb& c) const { cairo_set_source_rgb(cr(), c[0] / 255.0, c[1] / 255.0, c[2] / 255.0); }
  void fill_rect(double x, double y, double w, double h, const Rgb& c) const {
    colour(c);
    cairo_rectangle(cr(), x, y, w, h);
    cairo_fill(cr());
  }
  /// A line one pixel wide on the pixel row or column through integer (x, y) coordinates: sharp.
  void pixel_line(double x0, double y0, double x1, double y1, const Rgb& c) const {
    colour(c);
    cairo_set_line_width(cr(), 1.0);
    cairo_move_to(cr(), std::floor(x0) + 0.5, std::floor(y0) + 0.5);
    cairo_line_to(cr(), std::floor(x1) + 0.5, std::floor(y1) + 0.5);
    cairo_stroke(cr());
  }
  void line(double x0, double y0, double x1, double y1, double width, const Rgb& c) const {
    colour(c);
    cairo_set_line_width(cr(), width);
    cairo_set_line_cap(cr(), CAIRO_LINE_CAP_ROUND);
    cairo_move_to(cr(), x0, y0);
    cairo_line_to(cr(), x1, y1);
    cairo_stroke(cr());
  }
  void disc(double x, double y, double r, const Rgb& c) const {
    colour(c);
    cairo_arc(cr(), x, y, r, 0.0, 2.0 * M_PI);
    cairo_fill(cr());
  }
  void ring(double x, double y, double r, double width, const Rgb& c) const {
    colour(c);
    cairo_set_line_width(cr(), width);
    cairo_arc(cr(), x, y, r, 0.0, 2.0 * M_PI);
    cairo_stroke(cr());
  }

  [[nodiscard]] double text_width(const std::string& text, double size) const {
    cairo_set_font_size(cr(), size);
    cairo_text_extents_t extents;
    cairo_text_extents(cr(), text.c_str(), &extents);
    return extents.x_advance;
  }
  /// Text with its baseline at y, starting at x (align 0), centred on x (0.5) or ending at x (1).
  void text(double x, double y, const std::string& text, double size, const Rgb& c, double align = 0.0) const {
    colour(c);
    cairo_set_font_size(cr(), size);
    cairo_move_to(cr(), x - align * text_width(text, size), y);
    cairo_show_text(cr(), text.c_str());
  }
  /// Text read upwards (a quarter turn anticlockwise), centred on (x, y), its baseline at x.
  void text_up(double x, double y, const std::string& text, double size, const Rgb& c) const {
    cairo_save(cr());
    cairo_translate(cr(), x, y);
    cairo_rotate(cr(), -M_PI / 2.0);
    this->text(0.0, 0.0, text, size, c, 0.5);
    cairo_restore(cr());
  }

  /// The pixels as 8-bit RGB rows.
  [[nodiscard]] RgbImage take() const {
    cairo_surface_flush(m_surface.get());
    RgbImage image;
    image.width = cairo_image_surface_get_width(m_surface.get());
    image.height = cairo_image_surface_get_height(m_surface.get());
    image.rgb.resize(static_cast<std::size_t>(3 * image.width * image.height));
    const unsigned char* data = cairo_image_surface_get_data(m_surface.get());
    const int stride = cairo_image_surface_get_stride(m_surface.get());
    for (int y = 0; y < image.height; ++y) {
      const auto* row = reinterpret_cast<const std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
      for (int x = 0; x < image.width; ++x) {
        const std::uint32_t pixel = row[x];  // 0x00RRGGBB in the machine's byte order (CAIRO_FORMAT_RGB24)
        const auto at = static_cast<std::size_t>(3 * (y * image.width + x));
        image.rgb[at] = static_cast<std::uint8_t>(pixel >> 16);
        image.rgb[at + 1] = static_cast<std::uint8_t>(pixel >> 8);
        image.rgb[at + 2] = static_cast<std::uint8_t>(pixel);
      }
    }
    return image;
  }

 private:
  std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> m_surface;
  std::unique_ptr<cairo_t, void (*)(cairo_t*)> m_cr;
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

std::size_t note_characters(int width) {
  // DejaVu Sans at NOTE_SIZE: digits and lower case advance 6.5-7.7 px.
  return static_cast<std::size_t>(std::max(10.0, (width - 24.0) / (0.64 * NOTE_SIZE)));
}

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

// The plot area on the image, in pixels, and the log-log mapping into it.
struct PlotFrame {
  double left = 0.0, top = 50.0, right = 0.0, bottom = 0.0;
  Decades xd, yd;

  [[nodiscard]] double px(double x) const {
    return left + (std::log10(x) - xd.from) / (xd.to - xd.from) * (right - left);
  }
  [[nodiscard]] double py(double y) const {
    return bottom - (std::log10(y) - yd.from) / (yd.to - yd.from) * (bottom - top);
  }
  [[nodiscard]] double decade_x(int e) const { return std::round(px(std::pow(10.0, e))); }
  [[nodiscard]] double decade_y(int e) const { return std::round(py(std::pow(10.0, e))); }
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

// Layout: title on top, legend on the right, tick labels and titles left and below, notes last;
// the margins from the measured widths of the labels.
PlotFrame plot_frame(const Drawing& d, const LogLogPlot& plot) {
  const std::array<Decades, 2> axes = axis_decades(plot);
  double legend_width = d.text_width(plot.front_name, LABEL_SIZE);
  for (const std::string& name : plot.series) legend_width = std::max(legend_width, d.text_width(name, LABEL_SIZE));
  legend_width = std::min(legend_width + 40.0, 0.4 * plot.width);
  double y_labels = 0.0;
  for (int e = axes[1].first; e <= axes[1].last; ++e) y_labels = std::max(y_labels, d.text_width(decade_label(e), LABEL_SIZE));
  PlotFrame frame;
  frame.left = std::round(12.0 + LABEL_SIZE + 12.0 + y_labels + 10.0);  // y title, gap, tick labels, gap
  frame.right = std::round(plot.width - legend_width - 24.0);
  frame.bottom = std::round(plot.height - 66.0 - static_cast<double>(plot.notes.size()) * NOTE_LINE);
  if (frame.right - frame.left < 100 || frame.bottom - frame.top < 100) {
    throw std::invalid_argument("render_log_log_plot: too small");
  }
  frame.xd = axes[0];
  frame.yd = axes[1];
  return frame;
}

// Grid, ticks and their labels (thinned to about ten per axis), the frame and the axis titles.
void draw_axes(const Drawing& d, const PlotFrame& f, const LogLogPlot& plot) {
  const int x_every = std::max(1, (f.xd.last - f.xd.first + 9) / 10);
  const int y_every = std::max(1, (f.yd.last - f.yd.first + 9) / 10);
  for (int e = f.xd.first; e <= f.xd.last; ++e) {
    const double x = f.decade_x(e);
    d.pixel_line(x, f.top, x, f.bottom, GRID);
    d.pixel_line(x, f.bottom - 6, x, f.bottom, BLACK);
    if ((e - f.xd.first) % x_every == 0) d.text(x, f.bottom + 8 + LABEL_SIZE, decade_label(e), LABEL_SIZE, TEXT, 0.5);
    for (int m = 2; m <= 9 && e < f.xd.last && f.xd.last - f.xd.first <= 8; ++m) {
      const double minor = std::round(f.px(m * std::pow(10.0, e)));
      d.pixel_line(minor, f.bottom - 3, minor, f.bottom, BLACK);
    }
  }
  for (int e = f.yd.first; e <= f.yd.last; ++e) {
    const double y = f.decade_y(e);
    d.pixel_line(f.left, y, f.right, y, GRID);
    d.pixel_line(f.left, y, f.left + 6, y, BLACK);
    if ((e - f.yd.first) % y_every == 0) {
      d.text(f.left - 8, y + 0.36 * LABEL_SIZE, decade_label(e), LABEL_SIZE, TEXT, 1.0);
    }
    for (int m = 2; m <= 9 && e < f.yd.last && f.yd.last - f.yd.first <= 8; ++m) {
      const double minor = std::round(f.py(m * std::pow(10.0, e)));
      d.pixel_line(f.left, minor, f.left + 3, minor, BLACK);
    }
  }
  d.pixel_line(f.left, f.top, f.right, f.top, BLACK);
  d.pixel_line(f.left, f.bottom, f.right, f.bottom, BLACK);
  d.pixel_line(f.left, f.top, f.left, f.bottom, BLACK);
  d.pixel_line(f.right, f.top, f.right, f.bottom, BLACK);
  d.text((f.left + f.right) / 2.0, f.bottom + 44, plot.x_title, LABEL_SIZE, TEXT, 0.5);
  d.text_up(12.0 + LABEL_SIZE, (f.top + f.bottom) / 2.0, plot.y_title, LABEL_SIZE, TEXT);
}

// The front behind the points, then the points, then the rings.
void draw_points(const Drawing& d, const PlotFrame& f, const LogLogPlot& plot) {
  std::vector<std::size_t> front = plot.front;
  std::sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) {
    return plot.points[a].x < plot.points[b].x ||
           (plot.points[a].x == plot.points[b].x && plot.points[a].y > plot.points[b].y);
  });
  for (std::size_t k = 1; k < front.size(); ++k) {
    const PlotPoint& a = plot.points[front[k - 1]];
    const PlotPoint& b = plot.points[front[k]];
    d.line(f.px(a.x), f.py(a.y), f.px(b.x), f.py(b.y), 2.0, BLACK);
  }
  for (const PlotPoint& p : plot.points) d.disc(f.px(p.x), f.py(p.y), POINT_RADIUS, series_colour(p.series));
  for (const std::size_t k : front) d.ring(f.px(plot.points[k].x), f.py(plot.points[k].y), RING_RADIUS, RING_WIDTH, BLACK);
}

// One line per series, then the front's, right of the plot area.
void draw_legend(const Drawing& d, const PlotFrame& f, const LogLogPlot& plot) {
  const double line_height = LABEL_SIZE + 10.0;
  const double x = f.right + 18.0;
  double baseline = f.top + LABEL_SIZE;
  for (std::size_t k = 0; k < plot.series.size(); ++k, baseline += line_height) {
    d.disc(x + 10.0, baseline - 0.36 * LABEL_SIZE, POINT_RADIUS, series_colour(k));
    d.text(x + 26.0, baseline, plot.series[k], LABEL_SIZE, TEXT);
  }
  if (!plot.front.empty()) {
    const double middle = baseline - 0.36 * LABEL_SIZE;
    d.line(x, middle, x + 20.0, middle, 2.0, BLACK);
    d.ring(x + 10.0, middle, RING_RADIUS, RING_WIDTH, BLACK);
    d.text(x + 26.0, baseline, plot.front_name, LABEL_SIZE, TEXT);
  }
}

}  // namespace

RgbImage render_log_log_plot(const LogLogPlot& plot) {
  if (plot.width < 320 || plot.height < 240 || plot.width > 8192 || plot.height > 8192) {
    throw std::invalid_argument("render_log_log_plot: size must be 320 x 240 to 8192 x 8192");
  }
  const Drawing drawing(plot.width, plot.height);
  const PlotFrame frame = plot_frame(drawing, plot);
  drawing.fill_rect(0, 0, plot.width, plot.height, WHITE);
  drawing.text(plot.width / 2.0, 14.0 + TITLE_SIZE, plot.title, TITLE_SIZE, TEXT, 0.5);
  draw_axes(drawing, frame, plot);
  draw_points(drawing, frame, plot);
  draw_legend(drawing, frame, plot);
  double baseline = frame.bottom + 66.0 + NOTE_SIZE - 4.0;
  for (const std::string& note : plot.notes) {
    drawing.text(12.0, baseline, note, NOTE_SIZE, TEXT);
    baseline += NOTE_LINE;
  }
  return drawing.take();
}

}  // namespace tissue::host
