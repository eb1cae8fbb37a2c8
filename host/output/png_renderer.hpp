// png_renderer.hpp - a headless software rasterizer that draws a SurfaceFrame into an RGB image
// and writes it as PNG (libpng), for a picture of the surface without a display or GPU.
//
// Orthographic camera fitted to the surface's extent; z-buffered triangles with Lambert +
// ambient shading from a light fixed relative to the camera; mesh surface and cut faces in their
// own colours; back faces shaded too (dimmed), so that a cut body shows its inside; the tool as
// a thick depth-tested line; the force as an arrow from the contact point, drawn on top, and a
// bar of its magnitude. Supersampled (box filter). Deterministic: the same frame and settings
// give the same bytes.
#pragma once

#include "output/surface_frame.hpp"

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

namespace tissue::host {

using Rgb = std::array<std::uint8_t, 3>;

/// How render_surface draws: image size, camera, colours, lighting and overlays.
struct RenderSettings {
  int width = 1280;  ///< pixels, 1..16384
  int height = 960;  ///< pixels, 1..16384
  /// From the looked-at centre toward the camera (any length > 0); default above-front-side.
  std::array<double, 3> view_direction{1.0, -1.5, 1.2};
  /// World direction shown upwards; if (nearly) parallel to view_direction, +y, then +x is used.
  std::array<double, 3> up{0.0, 0.0, 1.0};
  /// Fraction of the width and of the height left free on each side of the surface, 0..0.45.
  double margin_fraction = 0.05;
  /// Box (min x y z, max x y z, metres) to fit instead of the surface, so that a sequence of
  /// frames can share one camera.
  std::optional<std::array<double, 6>> fit_box_m;
  /// Samples per pixel along each axis (1..4); 2 = 2x2 supersampling.
  int supersampling = 2;

  Rgb background{245, 246, 248};
  Rgb tissue_colour{150, 172, 96};  ///< mesh surface (frog skin)
  Rgb cut_colour{165, 25, 35};      ///< cut faces (deep red)
  /// Tool colour by tool_mode: none, probe, scalpel.
  std::array<Rgb, 3> tool_colours{{{125, 125, 130}, {55, 60, 75}, {185, 190, 200}}};
  Rgb force_colour{30, 90, 220};           ///< arrow, contact point and force bar
  Rgb force_overflow_colour{240, 140, 0};  ///< force bar when |F| > force_bar_max_n

  double ambient = 0.35;          ///< intensity everywhere, 0..1
  double diffuse = 0.65;          ///< Lambert intensity at normal incidence, 0..1
  double back_face_factor = 0.7;  ///< dimming of back faces (the inside of the surface), 0..1
  /// Vertex normals averaged over adjacent triangles of the same kind (mesh / cut) whose
  /// normals differ by at most crease_angle_deg; false = flat shading.
  bool smooth_shading = true;
  double crease_angle_deg = 40.0;

  double tool_width_px = 7.0;
  double force_scale_m_per_n = 0.01;  ///< arrow length per newton of force
  double arrow_width_px = 4.0;
  /// Full scale of the force bar (bottom left, drawn when has_tool or contact_active); 0 = no bar.
  double force_bar_max_n = 5.0;
};

/// Where the world lands in the image: orthographic, x right, y down, pixel centres at i + 0.5.
struct OrthographicView {
  std::array<double, 3> centre_m{};       ///< world point at the image centre
  std::array<double, 3> right{};          ///< unit, image +x
  std::array<double, 3> up{};             ///< unit, image -y
  std::array<double, 3> toward_viewer{};  ///< unit, right x up
  double metres_per_pixel = 1.0;
  int width = 0;
  int height = 0;

  /// (x px, y px, depth m toward the viewer from centre_m) of world point @p p_m.
  [[nodiscard]] std::array<double, 3> project(const std::array<double, 3>& p_m) const;
};

/// Row-major RGB, 8 bits per channel, top row first.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  ///< 3 * width * height

  [[nodiscard]] Rgb pixel(int x, int y) const;
};

/**
 * The camera render_surface uses: looking along -view_direction, with metres_per_pixel the
 * smallest that keeps the surface inside the image less its margins, and the surface centred.
 * "The surface" is the vertices the triangles reference (all vertices if there are no
 * triangles); with settings.fit_box_m it is that box's eight corners instead. Depths are
 * measured from the centre of the surface's bounding box. A surface that projects to a point
 * gets 1 m across the image's smaller usable side. Throws OutputError for an invalid frame or
 * settings.
 */
[[nodiscard]] OrthographicView fit_view(const SurfaceFrame& frame, const RenderSettings& settings);

/// Renders @p frame (see the file comment); throws OutputError for an invalid frame or settings.
[[nodiscard]] RgbImage render_surface(const SurfaceFrame& frame, const RenderSettings& settings = {});

/// The PNG file (8-bit RGB, no time stamp) of @p image; throws OutputError if libpng fails.
[[nodiscard]] std::vector<std::uint8_t> encode_png(const RgbImage& image);

/// Writes encode_png(@p image) to @p path (replacing it whole); throws OutputError.
void write_png(const std::filesystem::path& path, const RgbImage& image);

/// write_png(@p path, render_surface(@p frame, @p settings)).
void render_png(const std::filesystem::path& path, const SurfaceFrame& frame, const RenderSettings& settings = {});

}  // namespace tissue::host
