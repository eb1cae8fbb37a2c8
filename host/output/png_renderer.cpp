// png_renderer.cpp - software rasterizer (edge functions, z-buffer, box-filtered supersampling)
// and PNG encoding through libpng's simplified API (png_image_write_to_memory).
#include "output/png_renderer.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <utility>

namespace tissue::host {
namespace {

using Vec3 = std::array<double, 3>;

constexpr int MAX_IMAGE_SIDE = 16384;
constexpr int MAX_SUPERSAMPLING = 4;
constexpr double PI = 3.14159265358979323846;

Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 scaled(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
/// a / |a|, or zero for a zero vector.
Vec3 normalized(const Vec3& a) {
  const double length = norm(a);
  return length > 0.0 ? scaled(a, 1.0 / length) : Vec3{};
}

Vec3 vertex(const SurfaceFrame& frame, std::size_t v) {
  return {frame.positions_m[3 * v], frame.positions_m[3 * v + 1], frame.positions_m[3 * v + 2]};
}

bool finite3(const Vec3& a) { return std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]); }

void validate_settings(const RenderSettings& s) {
  const auto fail = [](const std::string& what) { throw OutputError("RenderSettings: " + what); };
  if (s.width < 1 || s.width > MAX_IMAGE_SIDE || s.height < 1 || s.height > MAX_IMAGE_SIDE) {
    fail("image " + std::to_string(s.width) + "x" + std::to_string(s.height) + " is not within 1..16384");
  }
  if (s.supersampling < 1 || s.supersampling > MAX_SUPERSAMPLING) {
    fail("supersampling " + std::to_string(s.supersampling) + " is not 1..4");
  }
  if (!finite3(s.view_direction) || !(norm(s.view_direction) > 0.0))
    fail("view_direction is not a finite non-zero vector");
  if (!finite3(s.up) || !(norm(s.up) > 0.0)) fail("up is not a finite non-zero vector");
  if (!(s.margin_fraction >= 0.0 && s.margin_fraction <= 0.45)) fail("margin_fraction is not 0..0.45");
  if (s.fit_box_m) {
    const auto& box = *s.fit_box_m;
    for (std::size_t i = 0; i < 3; ++i) {
      const double lo = box[i];
      const double hi = box[i + 3];
      if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi) fail("fit_box_m is not a finite box with min <= max");
    }
  }
  const auto unit = [](double x) { return x >= 0.0 && x <= 1.0; };
  if (!unit(s.ambient) || !unit(s.diffuse) || !unit(s.back_face_factor)) {
    fail("ambient, diffuse and back_face_factor must be 0..1");
  }
  if (!(s.crease_angle_deg >= 0.0 && s.crease_angle_deg <= 180.0)) fail("crease_angle_deg is not 0..180");
  if (!(s.tool_width_px >= 0.0 && s.tool_width_px <= 1000.0) ||
      !(s.arrow_width_px >= 0.0 && s.arrow_width_px <= 1000.0)) {
    fail("tool_width_px and arrow_width_px must be 0..1000");
  }
  if (!(s.force_scale_m_per_n >= 0.0) || !std::isfinite(s.force_scale_m_per_n)) {
    fail("force_scale_m_per_n is not finite and >= 0");
  }
  if (!(s.force_bar_max_n >= 0.0) || !std::isfinite(s.force_bar_max_n)) fail("force_bar_max_n is not finite and >= 0");
}

/// Camera axes for a view from @p view_direction with @p up shown upwards (or a fallback up).
void set_axes(OrthographicView& view, const Vec3& view_direction, const Vec3& up) {
  const Vec3 toward = normalized(view_direction);
  for (const Vec3& candidate : {normalized(up), Vec3{0.0, 1.0, 0.0}, Vec3{1.0, 0.0, 0.0}}) {
    const Vec3 right = cross(candidate, toward);
    if (norm(right) > 1e-6) {
      view.right = normalized(right);
      view.up = cross(toward, view.right);
      view.toward_viewer = cross(view.right, view.up);
      return;
    }
  }
}

/// Colour and depth at supersampled resolution.
class Canvas {
 public:
  Canvas(int width, int height, const Rgb& background)
      : m_width(width),
        m_height(height),
        m_rgb(3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height)),
        m_depth(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                -std::numeric_limits<double>::infinity()) {
    for (std::size_t i = 0; i < m_depth.size(); ++i) {
      std::copy(background.begin(), background.end(), m_rgb.begin() + static_cast<std::ptrdiff_t>(3 * i));
    }
  }
  [[nodiscard]] int width() const { return m_width; }
  [[nodiscard]] int height() const { return m_height; }

  /// Writes @p colour at (x, y) if @p depth is nearer than what is there (or always, when
  /// !depth_test); ties keep the earlier fragment, so the result does not depend on luck.
  void put(int x, int y, double depth, bool depth_test, const Rgb& colour) {
    const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(m_width) + static_cast<std::size_t>(x);
    if (depth_test) {
      if (!(depth > m_depth[i])) return;
      m_depth[i] = depth;
    }
    std::copy(colour.begin(), colour.end(), m_rgb.begin() + static_cast<std::ptrdiff_t>(3 * i));
  }

  /// Box filter of @p factor x @p factor samples per output pixel, rounded to nearest.
  [[nodiscard]] RgbImage downsample(int factor) const {
    RgbImage image;
    image.width = m_width / factor;
    image.height = m_height / factor;
    image.rgb.resize(3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height));
    const unsigned count = static_cast<unsigned>(factor * factor);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        for (std::size_t c = 0; c < 3; ++c) {
          unsigned sum = 0;
          for (int sy = 0; sy < factor; ++sy) {
            for (int sx = 0; sx < factor; ++sx) {
              sum += m_rgb[3 * (static_cast<std::size_t>(y * factor + sy) * static_cast<std::size_t>(m_width) +
                                static_cast<std::size_t>(x * factor + sx)) +
                           c];
            }
          }
          image.rgb[3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                         static_cast<std::size_t>(x)) +
                    c] = static_cast<std::uint8_t>((sum + count / 2) / count);
        }
      }
    }
    return image;
  }

 private:
  int m_width;
  int m_height;
  std::vector<std::uint8_t> m_rgb;
  std::vector<double> m_depth;
};

/// Sample-index range [first, last] of sample centres (i + 0.5) that may lie in [lo, hi].
std::pair<int, int> sample_range(double lo, double hi, int size) {
  if (std::isnan(lo) || std::isnan(hi)) return {0, -1};  // overflowed projection: draw nothing
  const double first = std::clamp(std::floor(lo - 0.5), 0.0, static_cast<double>(size));
  const double last = std::clamp(std::ceil(hi - 0.5), -1.0, static_cast<double>(size - 1));
  return {static_cast<int>(first), static_cast<int>(last)};
}

/// Twice the signed area of (a, b, p) in image coordinates.
double edge(const Vec3& a, const Vec3& b, double px, double py) {
  return (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
}

/// Of the two triangles sharing an edge (which run it in opposite directions), exactly one
/// owns the sample centres lying on it.
bool owns_edge(const Vec3& a, const Vec3& b) {
  const double dy = b[1] - a[1];
  return dy > 0.0 || (dy == 0.0 && b[0] < a[0]);
}

/**
 * Fills the image-space triangle @p s (x, y, depth per corner) on @p canvas. For each covered
 * sample, shade(b) gives the colour from the barycentric coordinates b of the corners as given.
 */
template <typename Shade>
void fill_triangle(Canvas& canvas, const std::array<Vec3, 3>& s, bool depth_test, Shade shade) {
  std::array<std::size_t, 3> order{0, 1, 2};
  double area = edge(s[0], s[1], s[2][0], s[2][1]);
  if (std::abs(area) < 1e-12) return;  // edge-on or degenerate: covers no area
  if (area < 0.0) {
    std::swap(order[1], order[2]);
    area = -area;
  }
  const Vec3& a = s[order[0]];
  const Vec3& b = s[order[1]];
  const Vec3& c = s[order[2]];
  const bool own_bc = owns_edge(b, c);
  const bool own_ca = owns_edge(c, a);
  const bool own_ab = owns_edge(a, b);
  const auto [x0, x1] = sample_range(std::min({a[0], b[0], c[0]}), std::max({a[0], b[0], c[0]}), canvas.width());
  const auto [y0, y1] = sample_range(std::min({a[1], b[1], c[1]}), std::max({a[1], b[1], c[1]}), canvas.height());
  const auto inside = [](double w, bool owned) { return w > 0.0 || (w == 0.0 && owned); };
  for (int y = y0; y <= y1; ++y) {
    const double py = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      const double wa = edge(b, c, px, py);
      const double wb = edge(c, a, px, py);
      const double wc = edge(a, b, px, py);
      if (!inside(wa, own_bc) || !inside(wb, own_ca) || !inside(wc, own_ab)) continue;
      std::array<double, 3> bary{};
      bary[order[0]] = wa / area;
      bary[order[1]] = wb / area;
      bary[order[2]] = wc / area;
      const double depth = bary[0] * s[0][2] + bary[1] * s[1][2] + bary[2] * s[2][2];
      canvas.put(x, y, depth, depth_test, shade(bary));
    }
  }
}

std::uint8_t channel(double value) { return static_cast<std::uint8_t>(std::lround(std::clamp(value, 0.0, 255.0))); }

Rgb times(const Rgb& colour, double factor) {
  return {channel(colour[0] * factor), channel(colour[1] * factor), channel(colour[2] * factor)};
}

/**
 * A segment of half-width @p radius between image points @p a and @p b (x, y, depth) with round
 * caps, shaded across its width like a cylinder lit from the front.
 */
void fill_capsule(Canvas& canvas, const Vec3& a, const Vec3& b, double radius, bool depth_test, const Rgb& colour) {
  if (!(radius > 0.0)) return;
  const auto [x0, x1] = sample_range(std::min(a[0], b[0]) - radius, std::max(a[0], b[0]) + radius, canvas.width());
  const auto [y0, y1] = sample_range(std::min(a[1], b[1]) - radius, std::max(a[1], b[1]) + radius, canvas.height());
  const double dx = b[0] - a[0];
  const double dy = b[1] - a[1];
  const double length2 = dx * dx + dy * dy;
  for (int y = y0; y <= y1; ++y) {
    const double py = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      const double t = length2 > 0.0 ? std::clamp(((px - a[0]) * dx + (py - a[1]) * dy) / length2, 0.0, 1.0) : 0.0;
      const double ex = px - (a[0] + t * dx);
      const double ey = py - (a[1] + t * dy);
      const double distance2 = ex * ex + ey * ey;
      if (distance2 > radius * radius) continue;
      const double shade = 0.6 + 0.4 * std::sqrt(1.0 - distance2 / (radius * radius));
      canvas.put(x, y, a[2] + t * (b[2] - a[2]), depth_test, times(colour, shade));
    }
  }
}

/// Unnormalized outward normals (twice the area) of the triangles.
std::vector<Vec3> face_normals(const SurfaceFrame& frame) {
  std::vector<Vec3> normals(frame.triangle_count());
  for (std::size_t t = 0; t < normals.size(); ++t) {
    const Vec3 p0 = vertex(frame, frame.triangles[3 * t]);
    normals[t] =
        cross(sub(vertex(frame, frame.triangles[3 * t + 1]), p0), sub(vertex(frame, frame.triangles[3 * t + 2]), p0));
  }
  return normals;
}

/**
 * Unit normal per triangle corner: the area-weighted mean of the normals of the triangles of the
 * same kind (mesh surface or cut face) around the corner's vertex that differ from this
 * triangle's by at most the crease angle, so that cube edges and the rim of a cut stay sharp.
 */
std::vector<Vec3> corner_normals(const SurfaceFrame& frame, const std::vector<Vec3>& faces, double crease_angle_deg) {
  const std::size_t triangle_count = faces.size();
  std::vector<Vec3> units(triangle_count);
  std::transform(faces.begin(), faces.end(), units.begin(), normalized);
  // Triangles around each vertex, compressed rows.
  std::vector<std::size_t> first(frame.vertex_count() + 1, 0);
  for (const std::uint32_t v : frame.triangles) ++first[v + 1];
  for (std::size_t v = 0; v + 1 < first.size(); ++v) first[v + 1] += first[v];
  std::vector<std::size_t> around(frame.triangles.size());
  std::vector<std::size_t> fill(first.begin(), first.end() - 1);
  for (std::size_t i = 0; i < frame.triangles.size(); ++i) around[fill[frame.triangles[i]]++] = i / 3;

  const double cos_crease = std::cos(crease_angle_deg * PI / 180.0);
  std::vector<Vec3> corners(frame.triangles.size());
  for (std::size_t i = 0; i < frame.triangles.size(); ++i) {
    const std::size_t t = i / 3;
    const bool cut = t >= frame.mesh_triangle_count;
    const std::uint32_t v = frame.triangles[i];
    Vec3 sum{};
    for (std::size_t k = first[v]; k < first[v + 1]; ++k) {
      const std::size_t other = around[k];
      if ((other >= frame.mesh_triangle_count) != cut) continue;
      if (dot(units[t], units[other]) + 1e-12 < cos_crease) continue;
      sum = add(sum, faces[other]);
    }
    const Vec3 unit = normalized(sum);
    corners[i] = norm(unit) > 0.0 ? unit : units[t];
  }
  return corners;
}

/// Bounding box (min, max) of the vertices the triangles reference (all if there are none).
std::pair<Vec3, Vec3> surface_box(const SurfaceFrame& frame) {
  constexpr double INF = std::numeric_limits<double>::infinity();
  Vec3 lo{INF, INF, INF};
  Vec3 hi{-INF, -INF, -INF};
  const auto grow = [&](std::size_t v) {
    const Vec3 p = vertex(frame, v);
    for (std::size_t c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], p[c]);
      hi[c] = std::max(hi[c], p[c]);
    }
  };
  if (!frame.triangles.empty()) {
    for (const std::uint32_t v : frame.triangles) grow(v);
  } else {
    for (std::size_t v = 0; v < frame.vertex_count(); ++v) grow(v);
  }
  if (!(lo[0] <= hi[0])) return {Vec3{}, Vec3{}};  // no vertices
  return {lo, hi};
}

void draw_force_bar(RgbImage& image, double force_n, const RenderSettings& settings) {
  const int margin = std::max(4, static_cast<int>(std::lround(0.02 * std::min(image.width, image.height))));
  const int bar_width = static_cast<int>(std::lround(0.3 * image.width));
  const int bar_height = std::max(6, static_cast<int>(std::lround(0.025 * image.height)));
  if (bar_width < 10 || bar_width + 2 * margin > image.width || bar_height + 2 * margin > image.height) return;
  const int left = margin;
  const int top = image.height - margin - bar_height;
  constexpr int BORDER = 2;
  const double fraction = force_n / settings.force_bar_max_n;
  const int inner_width = bar_width - 2 * BORDER;
  const int filled = static_cast<int>(std::lround(std::clamp(fraction, 0.0, 1.0) * inner_width));
  const Rgb border{60, 60, 60};
  const Rgb empty{255, 255, 255};
  const Rgb& fill_colour = fraction > 1.0 ? settings.force_overflow_colour : settings.force_colour;
  for (int y = top; y < top + bar_height; ++y) {
    for (int x = left; x < left + bar_width; ++x) {
      const bool on_border =
          y < top + BORDER || y >= top + bar_height - BORDER || x < left + BORDER || x >= left + bar_width - BORDER;
      const Rgb& colour = on_border ? border : (x - left - BORDER < filled ? fill_colour : empty);
      std::copy(colour.begin(), colour.end(),
                image.rgb.begin() + static_cast<std::ptrdiff_t>(
                                        3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                                             static_cast<std::size_t>(x))));
    }
  }
}

}  // namespace

std::array<double, 3> OrthographicView::project(const std::array<double, 3>& p_m) const {
  const Vec3 d = sub(p_m, centre_m);
  return {0.5 * width + dot(d, right) / metres_per_pixel, 0.5 * height - dot(d, up) / metres_per_pixel,
          dot(d, toward_viewer)};
}

Rgb RgbImage::pixel(int x, int y) const {
  const std::size_t i =
      3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x));
  return {rgb[i], rgb[i + 1], rgb[i + 2]};
}

OrthographicView fit_view(const SurfaceFrame& frame, const RenderSettings& settings) {
  validate_surface_frame(frame, "fit_view");
  validate_settings(settings);
  OrthographicView view;
  view.width = settings.width;
  view.height = settings.height;
  set_axes(view, settings.view_direction, settings.up);

  Vec3 lo;
  Vec3 hi;
  if (settings.fit_box_m) {
    const auto& box = *settings.fit_box_m;
    lo = {box[0], box[1], box[2]};
    hi = {box[3], box[4], box[5]};
  } else {
    std::tie(lo, hi) = surface_box(frame);
  }
  const Vec3 box_centre = scaled(add(lo, hi), 0.5);
  // Extent, in the image plane, of the box's corners or of the surface's vertices (tighter
  // than the box's corners when the view is oblique).
  constexpr double INF = std::numeric_limits<double>::infinity();
  std::array<double, 2> low{INF, INF};
  std::array<double, 2> high{-INF, -INF};
  const auto extend = [&](const Vec3& p) {
    const Vec3 d = sub(p, box_centre);
    const std::array<double, 2> xy{dot(d, view.right), dot(d, view.up)};
    for (std::size_t i = 0; i < 2; ++i) {
      low[i] = std::min(low[i], xy[i]);
      high[i] = std::max(high[i], xy[i]);
    }
  };
  if (settings.fit_box_m || frame.vertex_count() == 0) {
    for (int corner = 0; corner < 8; ++corner) {
      extend({(corner & 1) != 0 ? hi[0] : lo[0], (corner & 2) != 0 ? hi[1] : lo[1], (corner & 4) != 0 ? hi[2] : lo[2]});
    }
  } else if (!frame.triangles.empty()) {
    for (const std::uint32_t v : frame.triangles) extend(vertex(frame, v));
  } else {
    for (std::size_t v = 0; v < frame.vertex_count(); ++v) extend(vertex(frame, v));
  }
  view.centre_m =
      add(box_centre, add(scaled(view.right, 0.5 * (low[0] + high[0])), scaled(view.up, 0.5 * (low[1] + high[1]))));
  const double extent_x = high[0] - low[0];
  const double extent_y = high[1] - low[1];
  const double usable_width = settings.width * (1.0 - 2.0 * settings.margin_fraction);
  const double usable_height = settings.height * (1.0 - 2.0 * settings.margin_fraction);
  view.metres_per_pixel = std::max(extent_x / usable_width, extent_y / usable_height);
  if (!(view.metres_per_pixel > 0.0)) view.metres_per_pixel = 1.0 / std::min(usable_width, usable_height);
  return view;
}

RgbImage render_surface(const SurfaceFrame& frame, const RenderSettings& settings) {
  const OrthographicView view = fit_view(frame, settings);  // validates frame and settings
  const int ss = settings.supersampling;
  OrthographicView fine = view;
  fine.width = view.width * ss;
  fine.height = view.height * ss;
  fine.metres_per_pixel = view.metres_per_pixel / ss;
  Canvas canvas(fine.width, fine.height, settings.background);

  std::vector<Vec3> screen(frame.vertex_count());
  for (std::size_t v = 0; v < screen.size(); ++v) screen[v] = fine.project(vertex(frame, v));

  const std::vector<Vec3> faces = face_normals(frame);
  const std::vector<Vec3> corners =
      settings.smooth_shading ? corner_normals(frame, faces, settings.crease_angle_deg) : std::vector<Vec3>{};
  // A light above-left of the camera, fixed relative to it so that every view is lit alike and
  // what faces the camera is mostly lit.
  const Vec3 light =
      normalized(add(add(scaled(view.right, -0.15), scaled(view.up, 0.35)), scaled(view.toward_viewer, 1.0)));

  for (std::size_t t = 0; t < faces.size(); ++t) {
    const Vec3 face_unit = normalized(faces[t]);
    if (!(norm(face_unit) > 0.0)) continue;  // zero area
    const bool front = dot(face_unit, view.toward_viewer) >= 0.0;
    const Rgb& base = t < frame.mesh_triangle_count ? settings.tissue_colour : settings.cut_colour;
    const double side_factor = front ? 1.0 : settings.back_face_factor;
    const std::array<Vec3, 3> s{screen[frame.triangles[3 * t]], screen[frame.triangles[3 * t + 1]],
                                screen[frame.triangles[3 * t + 2]]};
    fill_triangle(canvas, s, true, [&](const std::array<double, 3>& bary) {
      Vec3 n = face_unit;
      if (!corners.empty()) {
        n = normalized(add(add(scaled(corners[3 * t], bary[0]), scaled(corners[3 * t + 1], bary[1])),
                           scaled(corners[3 * t + 2], bary[2])));
      }
      if (!front) n = scaled(n, -1.0);  // the inside is lit as seen from the camera's side
      const double lambert = std::max(0.0, dot(n, light));
      return times(base, (settings.ambient + settings.diffuse * lambert) * side_factor);
    });
  }

  if (frame.has_tool) {
    const Rgb& colour = settings.tool_colours[static_cast<std::size_t>(frame.tool_mode)];
    fill_capsule(canvas, fine.project(frame.tool_tip_m), fine.project(frame.tool_handle_m),
                 0.5 * settings.tool_width_px * ss, true, colour);
  }
  double force_magnitude_n = 0.0;
  if (frame.contact_active) {
    force_magnitude_n = norm(frame.force_n);
    // The force arrow and the contact point are drawn over everything: they must stay visible.
    const Vec3 from = fine.project(frame.contact_point_m);
    const Vec3 to = fine.project(add(frame.contact_point_m, scaled(frame.force_n, settings.force_scale_m_per_n)));
    const double width = settings.arrow_width_px * ss;
    fill_capsule(canvas, from, from, 1.2 * width, false, settings.force_colour);
    const double dx = to[0] - from[0];
    const double dy = to[1] - from[1];
    const double length = std::sqrt(dx * dx + dy * dy);
    if (length >= 1.0) {
      const double head = std::min(length, std::max(4.0 * width, 0.25 * length));
      const double ux = dx / length;
      const double uy = dy / length;
      const Vec3 base{to[0] - ux * head, to[1] - uy * head, 0.0};
      fill_capsule(canvas, from, base, 0.5 * width, false, settings.force_colour);
      const double half = 1.5 * width;
      const std::array<Vec3, 3> tip{to, Vec3{base[0] - uy * half, base[1] + ux * half, 0.0},
                                    Vec3{base[0] + uy * half, base[1] - ux * half, 0.0}};
      fill_triangle(canvas, tip, false, [&](const std::array<double, 3>&) { return settings.force_colour; });
    }
  }

  RgbImage image = canvas.downsample(ss);
  if ((frame.has_tool || frame.contact_active) && settings.force_bar_max_n > 0.0) {
    draw_force_bar(image, force_magnitude_n, settings);
  }
  return image;
}

std::vector<std::uint8_t> encode_png(const RgbImage& image) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw OutputError("encode_png: image " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                      " with " + std::to_string(image.rgb.size()) + " bytes is not a valid RGB image");
  }
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  // Room for the image stored uncompressed (filter bytes and chunk overhead included), so that
  // one pass normally suffices; libpng reports the size it needs if not.
  const std::size_t raw = image.rgb.size() + static_cast<std::size_t>(image.height);
  std::vector<std::uint8_t> bytes(raw + raw / 16 + 4096);
  png_alloc_size_t size = bytes.size();
  if (png_image_write_to_memory(&png, bytes.data(), &size, 0, image.rgb.data(), 0, nullptr) == 0) {
    if (size <= bytes.size()) throw OutputError(std::string("encode_png: libpng: ") + png.message);
    bytes.resize(size);
    if (png_image_write_to_memory(&png, bytes.data(), &size, 0, image.rgb.data(), 0, nullptr) == 0) {
      throw OutputError(std::string("encode_png: libpng: ") + png.message);
    }
  }
  bytes.resize(size);
  return bytes;
}

void write_png(const std::filesystem::path& path, const RgbImage& image) {
  const std::vector<std::uint8_t> bytes = encode_png(image);
  write_output_file(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

void render_png(const std::filesystem::path& path, const SurfaceFrame& frame, const RenderSettings& settings) {
  write_png(path, render_surface(frame, settings));
}

}  // namespace tissue::host
