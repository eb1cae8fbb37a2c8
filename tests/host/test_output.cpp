// test_output.cpp - host/output/: VTU frames and the PVD index parsed back with an XML reader,
// and the PNG renderer measured: covered pixels against the analytic projected area of a cube,
// cut faces in the cut colour, hidden faces hidden, insides shown, determinism and refusals.
#include "output/png_renderer.hpp"
#include "output/pvd_writer.hpp"
#include "output/session_summary.hpp"
#include "output/surface_frame.hpp"
#include "output/vtu_writer.hpp"
#include "host/vtu_read.hpp"

#include <png.h>
#include <pugixml.hpp>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace tissue::host {
namespace {

// SurfaceFrame::tool_mode values (the Tissue FMU's ToolMode enumeration).
constexpr int TOOL_MODE_PROBE = 1;
constexpr int TOOL_MODE_SCALPEL = 2;

/// A fresh directory under the system temporary directory, removed with its content.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "tissue-output-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    m_path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(m_path, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  TempDir(TempDir&&) = delete;
  TempDir& operator=(TempDir&&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// ---------------------------------------------------------------------------------------------
// Frames

/// A tetrahedron's 4 outward faces plus one cut face on its own 3 vertices; coordinates chosen
/// to need all 17 significant digits (1/3, 0.1) and a negative zero.
SurfaceFrame tetrahedron_with_cut() {
  SurfaceFrame frame;
  frame.time_s = 0.125;
  frame.positions_m = {0.0,  0.0, 0.0,        0.1, 0.0, 0.0,        0.0,
                       0.1,  0.0, 0.0,        0.0, 0.1, 1.0 / 30.0, 0.0,
                       -0.0, 0.0, 1.0 / 30.0, 0.0, 0.0, 0.0,        1.0 / 3.0 * 0.1};
  frame.triangles = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 4, 5, 6};
  frame.mesh_triangle_count = 4;
  return frame;
}

enum CubeFace : int { BOTTOM = 0, TOP, FRONT, BACK, LEFT, RIGHT };

/**
 * An axis-aligned cube [0, side]^3, counter-clockwise seen from outside. Vertex i is at
 * side * (bit 0, bit 1, bit 2 of i). @p cut_face (if any) is put last and counted as a cut face;
 * @p omitted_face (if any) is left out, making an open box.
 */
SurfaceFrame cube(double side, std::optional<CubeFace> cut_face = std::nullopt,
                  std::optional<CubeFace> omitted_face = std::nullopt) {
  SurfaceFrame frame;
  for (int v = 0; v < 8; ++v) {
    frame.positions_m.push_back(side * (v & 1));
    frame.positions_m.push_back(side * ((v >> 1) & 1));
    frame.positions_m.push_back(side * ((v >> 2) & 1));
  }
  // Quads (a b c d) by CubeFace: -z, +z, -y, +y, -x, +x.
  const std::array<std::array<std::uint32_t, 4>, 6> quads{
      {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}}};
  const auto append = [&frame](const std::array<std::uint32_t, 4>& q) {
    frame.triangles.insert(frame.triangles.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  };
  for (int f = 0; f < 6; ++f) {
    if (f == cut_face || f == omitted_face) continue;
    append(quads[static_cast<std::size_t>(f)]);
  }
  frame.mesh_triangle_count = frame.triangle_count();
  if (cut_face) append(quads[static_cast<std::size_t>(*cut_face)]);
  return frame;
}

// ---------------------------------------------------------------------------------------------
// VTU

/// The DataArray named @p name anywhere under @p parent.
pugi::xml_node data_array(const pugi::xml_node& parent, const char* name) {
  return parent.find_child_by_attribute("DataArray", "Name", name);
}

/// The values of a DataArray node, in whichever format it is written (vtu_read.hpp).
std::vector<double> values(const pugi::xml_node& array) {
  return vtu_read::data_array_values(array.attribute("type").value(), array.attribute("format").value(), array.child_value());
}

// summary.json parses back to the summary's own values: text with quotes, backslashes, control
// characters and bytes that are not UTF-8 (a device's name, an error from a library), numbers at
// full precision, and null for the figures of a hand that never settled (NaN).
TEST(SessionSummary, JsonParsesBackToItsValues) {
  SessionSummary s;
  s.scenario = "a \"quoted\" \\ name\twith\ncontrols";
  s.sim_time_s = 1.0 / 3.0;
  s.tissue_step_ms = {0.123456789012, 1.5e-7, 12345.678901234};
  s.haptic_ticks = 18446744073709551615ULL;
  s.device_name = "udp \xff\xfe";
  s.first_error = "CHOLMOD: \"not positive definite\"";
  HandFigures hand;
  hand.settle_time_s = std::numeric_limits<double>::quiet_NaN();
  hand.device_work_j = -0.0012345678901234;
  hand.mean_force_n = {0.1, -0.2, std::numeric_limits<double>::infinity()};
  s.hand = hand;
  const nlohmann::json j = nlohmann::json::parse(s.to_json());
  EXPECT_EQ(j["scenario"].get<std::string>(), s.scenario);
  EXPECT_EQ(j["sim_time_s"].get<double>(), s.sim_time_s);
  EXPECT_EQ(j["tissue_step_ms"]["p50"].get<double>(), s.tissue_step_ms.p50);
  EXPECT_EQ(j["tissue_step_ms"]["p99"].get<double>(), s.tissue_step_ms.p99);
  EXPECT_EQ(j["tissue_step_ms"]["max"].get<double>(), s.tissue_step_ms.max);
  EXPECT_EQ(j["haptic_ticks"].get<std::uint64_t>(), s.haptic_ticks);
  EXPECT_EQ(j["first_error"].get<std::string>(), s.first_error);
  EXPECT_TRUE(j["device"]["name"].is_string());  // the bad bytes replaced, the rest kept
  EXPECT_EQ(j["device"]["name"].get<std::string>().rfind("udp ", 0), 0u);
  EXPECT_TRUE(j["hand"]["settle_time_s"].is_null());
  EXPECT_EQ(j["hand"]["device_work_J"].get<double>(), hand.device_work_j);
  EXPECT_EQ(j["hand"]["mean_force_N"][1].get<double>(), -0.2);
  EXPECT_TRUE(j["hand"]["mean_force_N"][2].is_null());
  EXPECT_FALSE(j.contains("view"));
  EXPECT_EQ(nlohmann::ordered_json::parse(s.to_json()).begin().key(), "scenario");  // keys in their old order
}

TEST(VtuWriter, TetrahedronWithCutFaceParsesBack) {
  const SurfaceFrame frame = tetrahedron_with_cut();
  const std::string text = vtu_document(frame);
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_string(text.c_str())) << text;
  const pugi::xml_node file = doc.child("VTKFile");
  EXPECT_STREQ(file.attribute("type").value(), "UnstructuredGrid");
  const pugi::xml_node grid = file.child("UnstructuredGrid");
  const pugi::xml_node piece = grid.child("Piece");
  EXPECT_EQ(piece.attribute("NumberOfPoints").as_int(), 7);
  EXPECT_EQ(piece.attribute("NumberOfCells").as_int(), 5);

  const pugi::xml_node points = data_array(piece.child("Points"), "Points");
  EXPECT_STREQ(points.attribute("type").value(), "Float64");
  EXPECT_EQ(points.attribute("NumberOfComponents").as_int(), 3);
  EXPECT_STREQ(points.attribute("format").value(), "binary");  // exact values, a third the text of decimals
  const std::vector<double> xyz = values(points);
  ASSERT_EQ(xyz.size(), frame.positions_m.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) EXPECT_EQ(xyz[i], frame.positions_m[i]) << "coordinate " << i;

  const pugi::xml_node cells = piece.child("Cells");
  const std::vector<double> connectivity = values(data_array(cells, "connectivity"));
  ASSERT_EQ(connectivity.size(), frame.triangles.size());
  for (std::size_t i = 0; i < connectivity.size(); ++i) EXPECT_EQ(connectivity[i], frame.triangles[i]);
  EXPECT_EQ(values(data_array(cells, "offsets")), (std::vector<double>{3, 6, 9, 12, 15}));
  const pugi::xml_node types = data_array(cells, "types");
  EXPECT_STREQ(types.attribute("type").value(), "UInt8");
  EXPECT_EQ(values(types), (std::vector<double>{5, 5, 5, 5, 5}));  // VTK_TRIANGLE

  const pugi::xml_node cell_data = piece.child("CellData");
  EXPECT_STREQ(cell_data.attribute("Scalars").value(), "cut_face");
  EXPECT_EQ(values(data_array(cell_data, "cut_face")), (std::vector<double>{0, 0, 0, 0, 1}));

  const pugi::xml_node time = data_array(grid.child("FieldData"), "TimeValue");
  EXPECT_EQ(values(time), std::vector<double>{0.125});
  EXPECT_FALSE(data_array(grid.child("FieldData"), "tool_tip_m"));
  EXPECT_FALSE(data_array(grid.child("FieldData"), "force_n"));
}

TEST(VtuWriter, EqualFramesGiveByteIdenticalFiles) {
  const TempDir dir;
  SurfaceFrame frame = tetrahedron_with_cut();
  write_vtu(dir.path() / "a.vtu", frame);
  write_vtu(dir.path() / "b.vtu", tetrahedron_with_cut());
  const std::string a = read_bytes(dir.path() / "a.vtu");
  EXPECT_FALSE(a.empty());
  EXPECT_EQ(a, read_bytes(dir.path() / "b.vtu"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "a.vtu.partial"));
  // A different coordinate in the last bit changes the file: the format loses nothing.
  frame.positions_m[3] = std::nextafter(frame.positions_m[3], 1.0);
  EXPECT_NE(vtu_document(frame), a);
}

TEST(VtuWriter, ToolAndContactGoToFieldData) {
  SurfaceFrame frame = tetrahedron_with_cut();
  frame.has_tool = true;
  frame.tool_tip_m = {0.01, 0.02, 0.03};
  frame.tool_handle_m = {0.01, 0.02, 0.13};
  frame.tool_mode = TOOL_MODE_SCALPEL;
  frame.contact_active = true;
  frame.contact_point_m = {0.01, 0.02, 0.025};
  frame.force_n = {0.0, -0.5, 1.25};
  pugi::xml_document doc;
  const std::string text = vtu_document(frame);
  ASSERT_TRUE(doc.load_string(text.c_str()));
  const pugi::xml_node field = doc.child("VTKFile").child("UnstructuredGrid").child("FieldData");
  EXPECT_EQ(values(data_array(field, "tool_tip_m")), (std::vector<double>{0.01, 0.02, 0.03}));
  EXPECT_EQ(values(data_array(field, "tool_handle_m")), (std::vector<double>{0.01, 0.02, 0.13}));
  EXPECT_EQ(values(data_array(field, "tool_mode")), std::vector<double>{2});
  EXPECT_EQ(values(data_array(field, "contact_point_m")), (std::vector<double>{0.01, 0.02, 0.025}));
  EXPECT_EQ(values(data_array(field, "force_n")), (std::vector<double>{0.0, -0.5, 1.25}));
  EXPECT_EQ(data_array(field, "force_n").attribute("NumberOfComponents").as_int(), 3);
}

TEST(VtuWriter, RefusesInvalidFramesAndWritesNothing) {
  const TempDir dir;
  const auto refused = [&dir](const SurfaceFrame& frame) {
    EXPECT_THROW(write_vtu(dir.path() / "bad.vtu", frame), OutputError);
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "bad.vtu"));
  };
  SurfaceFrame frame = tetrahedron_with_cut();
  frame.positions_m[4] = std::numeric_limits<double>::quiet_NaN();
  refused(frame);
  frame = tetrahedron_with_cut();
  frame.positions_m[0] = std::numeric_limits<double>::infinity();
  refused(frame);
  frame = tetrahedron_with_cut();
  frame.triangles[14] = 7;  // one past the last vertex
  refused(frame);
  frame = tetrahedron_with_cut();
  frame.mesh_triangle_count = 6;
  refused(frame);
  frame = tetrahedron_with_cut();
  frame.positions_m.pop_back();
  refused(frame);
  frame = tetrahedron_with_cut();
  frame.contact_active = true;
  frame.force_n[1] = std::numeric_limits<double>::quiet_NaN();
  refused(frame);
  try {
    frame = tetrahedron_with_cut();
    frame.triangles[14] = 7;
    (void)vtu_document(frame);
    ADD_FAILURE() << "an index out of range was accepted";
  } catch (const OutputError& error) {
    EXPECT_NE(std::string(error.what()).find("triangle 4 references vertex 7 of 7"), std::string::npos) << error.what();
  }
  EXPECT_THROW(write_vtu(dir.path() / "no-such-dir" / "a.vtu", tetrahedron_with_cut()), OutputError);
}

// ---------------------------------------------------------------------------------------------
// PVD

TEST(PvdWriter, ListsTheFramesWithTheirTimes) {
  EXPECT_EQ(frame_file_name("frame", 42), "frame_000042.vtu");
  EXPECT_EQ(frame_file_name("run", 1234567), "run_1234567.vtu");
  PvdWriter pvd;
  pvd.add(0.0, frame_file_name("frame", 0));
  pvd.add(0.1, frame_file_name("frame", 1));
  pvd.add(1.0 / 3.0, "frames/a&b.vtu");
  EXPECT_EQ(pvd.size(), 3U);
  pugi::xml_document doc;
  const std::string text = pvd.document();
  ASSERT_TRUE(doc.load_string(text.c_str())) << text;
  EXPECT_STREQ(doc.child("VTKFile").attribute("type").value(), "Collection");
  std::vector<double> times;
  std::vector<std::string> files;
  for (const pugi::xml_node set : doc.child("VTKFile").child("Collection").children("DataSet")) {
    times.push_back(std::strtod(set.attribute("timestep").value(), nullptr));
    files.emplace_back(set.attribute("file").value());
    EXPECT_STREQ(set.attribute("part").value(), "0");
  }
  EXPECT_EQ(times, (std::vector<double>{0.0, 0.1, 1.0 / 3.0}));
  EXPECT_EQ(files, (std::vector<std::string>{"frame_000000.vtu", "frame_000001.vtu", "frames/a&b.vtu"}));

  const TempDir dir;
  pvd.write(dir.path() / "a.pvd");
  pvd.write(dir.path() / "b.pvd");
  EXPECT_EQ(read_bytes(dir.path() / "a.pvd"), text);
  EXPECT_EQ(read_bytes(dir.path() / "b.pvd"), text);
}

TEST(PvdWriter, RefusesTimesOutOfOrderAndBadNames) {
  PvdWriter pvd;
  pvd.add(0.5, "a.vtu");
  EXPECT_THROW(pvd.add(0.5, "b.vtu"), OutputError);
  EXPECT_THROW(pvd.add(0.25, "b.vtu"), OutputError);
  EXPECT_THROW(pvd.add(std::numeric_limits<double>::quiet_NaN(), "b.vtu"), OutputError);
  EXPECT_THROW(pvd.add(std::numeric_limits<double>::infinity(), "b.vtu"), OutputError);
  EXPECT_THROW(pvd.add(1.0, ""), OutputError);
  EXPECT_THROW(pvd.add(1.0, "/tmp/b.vtu"), OutputError);
  EXPECT_THROW(pvd.add(1.0, "b\n.vtu"), OutputError);
  EXPECT_EQ(pvd.size(), 1U);
  pvd.add(1.0, "b.vtu");
  EXPECT_EQ(pvd.size(), 2U);
}

// ---------------------------------------------------------------------------------------------
// PNG

bool is_background(const Rgb& pixel, const RenderSettings& settings) { return pixel == settings.background; }
/// Deep red: the cut colour at any shading, not blended with green tissue or the background.
bool is_cut(const Rgb& p) { return p[0] > 20 && p[0] >= 2 * p[1] && p[0] >= 2 * p[2]; }
/// Green dominant: the tissue colour at any shading, alone or blended with the background.
bool is_tissue(const Rgb& p) { return p[1] > p[0] && p[1] > p[2]; }

template <typename Predicate>
long count_pixels(const RgbImage& image, Predicate predicate) {
  long count = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) count += predicate(image.pixel(x, y)) ? 1 : 0;
  }
  return count;
}

long covered_pixels(const RgbImage& image, const RenderSettings& settings) {
  return count_pixels(image, [&](const Rgb& p) { return !is_background(p, settings); });
}

/**
 * The pixels a convex polygon's outline can cross: its edges advance by sum |dx| = 2 w and
 * sum |dy| = 2 h over the polygon (w x h its projected bounding box), each crossing at most one
 * new pixel per unit step, plus one per corner. Only these pixels are partly covered, so
 * counting each as covered or not (by its samples) errs by at most this many.
 */
double outline_pixels(const OrthographicView& view, const SurfaceFrame& frame, std::size_t corners) {
  double lo_x = 1e300;
  double hi_x = -1e300;
  double lo_y = 1e300;
  double hi_y = -1e300;
  for (const std::uint32_t index : frame.triangles) {
    const std::size_t v = index;
    const auto p = view.project({frame.positions_m[3 * v], frame.positions_m[3 * v + 1], frame.positions_m[3 * v + 2]});
    lo_x = std::min(lo_x, p[0]);
    hi_x = std::max(hi_x, p[0]);
    lo_y = std::min(lo_y, p[1]);
    hi_y = std::max(hi_y, p[1]);
  }
  return 2.0 * (hi_x - lo_x) + 2.0 * (hi_y - lo_y) + static_cast<double>(corners);
}

RenderSettings small_settings(int width, int height, std::array<double, 3> view_direction, std::array<double, 3> up) {
  RenderSettings settings;
  settings.width = width;
  settings.height = height;
  settings.view_direction = view_direction;
  settings.up = up;
  return settings;
}

TEST(PngRenderer, CubeFromAboveCoversItsProjectedArea) {
  constexpr double SIDE = 0.02;
  const SurfaceFrame frame = cube(SIDE);
  // 301 rows and a 7 % margin put the square's edges inside pixels, not on their borders.
  RenderSettings settings = small_settings(400, 301, {0, 0, 1}, {0, 1, 0});
  settings.margin_fraction = 0.07;
  // Analytic fit: the unit square's bounding box fills the usable height 301 * (1 - 0.14).
  const double side_px = 301 * (1 - 2 * 0.07);
  const OrthographicView view = fit_view(frame, settings);
  EXPECT_NEAR(view.metres_per_pixel, SIDE / side_px, 1e-15);

  const RgbImage image = render_surface(frame, settings);
  ASSERT_EQ(image.width, 400);
  ASSERT_EQ(image.height, 301);
  const double area_px = side_px * side_px;
  // Only pixels the outline crosses are in doubt: one ring of at most 4 (L + 1) pixels.
  const double ring = 4.0 * (side_px + 1.0);
  const double covered = static_cast<double>(covered_pixels(image, settings));
  EXPECT_NEAR(covered, area_px, ring);

  // Fractional coverage from the blend with the background (the top is uniformly lit): 2x2
  // samples misjudge an edge pixel by at most 1/4, so the sum errs by at most ring / 4.
  const Rgb face = image.pixel(200, 150);
  double coverage = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const Rgb p = image.pixel(x, y);
      coverage += (settings.background[1] - p[1]) / static_cast<double>(settings.background[1] - face[1]);
    }
  }
  EXPECT_NEAR(coverage, area_px, ring / 4.0);
  EXPECT_EQ(count_pixels(image, is_cut), 0);
}

TEST(PngRenderer, ObliqueCubeCoversItsProjectedArea) {
  constexpr double SIDE = 0.05;
  const SurfaceFrame frame = cube(SIDE);
  const std::array<double, 3> direction{1.0, -1.5, 1.2};
  const RenderSettings settings = small_settings(640, 480, direction, {0, 0, 1});
  const OrthographicView view = fit_view(frame, settings);
  // A convex body's projected area along unit d is half its surface's integral of |n . d|:
  // for a cube, side^2 (|dx| + |dy| + |dz|).
  const double length =
      std::sqrt(direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]);
  const double area_m2 =
      SIDE * SIDE * (std::abs(direction[0]) + std::abs(direction[1]) + std::abs(direction[2])) / length;
  const double area_px = area_m2 / (view.metres_per_pixel * view.metres_per_pixel);
  const double outline = outline_pixels(view, frame, 6);
  const double covered = static_cast<double>(covered_pixels(render_surface(frame, settings), settings));
  EXPECT_NEAR(covered, area_px, outline);
  EXPECT_GT(area_px, 0.3 * 640 * 480);  // the fit fills the image
}

TEST(PngRenderer, CutFacesAppearInTheCutColour) {
  constexpr double SIDE = 0.03;
  const SurfaceFrame frame = cube(SIDE, TOP);
  ASSERT_EQ(frame.mesh_triangle_count, 10U);

  // From above only the cut top shows.
  RenderSettings above = small_settings(300, 300, {0, 0, 1}, {0, 1, 0});
  above.margin_fraction = 0.1;
  const double side_px = 300 * 0.8;
  const RgbImage top = render_surface(frame, above);
  const double cut = static_cast<double>(count_pixels(top, is_cut));
  EXPECT_GE(cut, (side_px - 2) * (side_px - 2));  // all but a ring of edge pixels
  EXPECT_LE(cut, side_px * side_px);
  EXPECT_EQ(count_pixels(top, is_tissue), 0);

  // Obliquely the cut top is a parallelogram of area side^2 |dz| / |d|, next to green sides.
  const std::array<double, 3> direction{1.0, -1.5, 1.2};
  const RenderSettings oblique = small_settings(640, 480, direction, {0, 0, 1});
  const OrthographicView view = fit_view(frame, oblique);
  const RgbImage image = render_surface(frame, oblique);
  const double length = std::sqrt(1.0 + 2.25 + 1.44);
  const double top_px = SIDE * SIDE * 1.2 / length / (view.metres_per_pixel * view.metres_per_pixel);
  SurfaceFrame top_only;
  top_only.positions_m = frame.positions_m;
  top_only.triangles = {4, 5, 7, 4, 7, 6};
  const double outline = outline_pixels(view, top_only, 4);
  const double oblique_cut = static_cast<double>(count_pixels(image, is_cut));
  EXPECT_NEAR(oblique_cut, top_px, outline);
  EXPECT_GT(count_pixels(image, is_tissue), static_cast<long>(top_px));  // two sides show, each larger
}

TEST(PngRenderer, DepthBufferHidesFacesBehind) {
  constexpr double SIDE = 1.0;
  const SurfaceFrame frame = cube(SIDE, BOTTOM);  // the cut face is at the bottom
  RenderSettings settings = small_settings(200, 200, {0, 0, 1}, {0, 1, 0});
  settings.margin_fraction = 0.1;
  const double side_px = 160;
  // The cut bottom is drawn last, behind the top: the depth test must reject it.
  EXPECT_EQ(count_pixels(render_surface(frame, settings), is_cut), 0);
  settings.view_direction = {0, 0, -1};
  const double cut = static_cast<double>(count_pixels(render_surface(frame, settings), is_cut));
  EXPECT_GE(cut, (side_px - 2) * (side_px - 2));
  EXPECT_LE(cut, side_px * side_px);
}

TEST(PngRenderer, OpenBoxShowsItsDimmedInside) {
  constexpr double SIDE = 1.0;
  RenderSettings settings = small_settings(200, 200, {0, 0, 1}, {0, 1, 0});
  settings.margin_fraction = 0.1;
  const RgbImage closed = render_surface(cube(SIDE), settings);
  const RgbImage open = render_surface(cube(SIDE, std::nullopt, TOP), settings);
  // The bottom is seen from inside (a back face) and covers the same square.
  EXPECT_EQ(covered_pixels(open, settings), covered_pixels(closed, settings));
  // Lit with its normal flipped toward the camera, it is the top's colour times the dimming.
  const Rgb inside = open.pixel(100, 100);
  const Rgb outside = closed.pixel(100, 100);
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_NEAR(inside[c], settings.back_face_factor * outside[c], 1.0) << "channel " << c;
  }
  EXPECT_TRUE(is_tissue(inside));
}

/// The cube from the front (-y) with a probe above its top and a force of 2 N up at the top centre.
SurfaceFrame cube_with_tool(bool contact) {
  SurfaceFrame frame = cube(1.0);
  frame.has_tool = true;
  frame.tool_mode = TOOL_MODE_PROBE;
  frame.tool_tip_m = {0.25, 0.5, 1.0};
  frame.tool_handle_m = {0.25, 0.5, 1.3};
  frame.contact_active = contact;
  frame.contact_point_m = {0.6, 0.5, 1.0};
  frame.force_n = {0.0, 0.0, 2.0};
  return frame;
}

TEST(PngRenderer, DrawsTheToolTheForceArrowAndTheForceBar) {
  RenderSettings settings = small_settings(400, 400, {0, -1, 0}, {0, 0, 1});
  settings.margin_fraction = 0.2;
  settings.force_scale_m_per_n = 0.1;  // 2 N -> 0.2 m = 48 px
  settings.force_bar_max_n = 5.0;
  const SurfaceFrame frame = cube_with_tool(true);
  const OrthographicView view = fit_view(frame, settings);
  ASSERT_NEAR(view.metres_per_pixel, 1.0 / 240.0, 1e-15);
  const RgbImage image = render_surface(frame, settings);
  const auto at = [&](const std::array<double, 3>& p_m) {
    const auto p = view.project(p_m);
    return image.pixel(static_cast<int>(p[0]), static_cast<int>(p[1]));
  };
  // The probe's shaft, above the cube: its own dark colour.
  const Rgb shaft = at({0.25, 0.5, 1.15});
  const Rgb probe = settings.tool_colours[1];
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_LE(shaft[c], probe[c]) << "channel " << c;
    EXPECT_GE(shaft[c], 0.6 * probe[c] - 1) << "channel " << c;
  }
  // The arrow, over the cube and above it, and the bar's filled 2/5 at the bottom left.
  const auto blue = [](const Rgb& p) { return p[2] > 150 && p[0] < 100; };
  EXPECT_TRUE(blue(at({0.6, 0.5, 1.0})));    // contact point
  EXPECT_TRUE(blue(at({0.6, 0.5, 1.08})));   // shaft
  EXPECT_TRUE(blue(at({0.6, 0.5, 1.19})));   // head
  EXPECT_FALSE(blue(at({0.6, 0.5, 1.23})));  // beyond the tip
  const int bar_row = 400 - 8 - 5;           // margin 8 px, bar 10 px high
  EXPECT_TRUE(blue(image.pixel(8 + 2 + 10, bar_row)));
  EXPECT_EQ(image.pixel(8 + 2 + 70, bar_row), (Rgb{255, 255, 255}));

  // Without contact: no arrow, an empty bar, and the probe is still drawn.
  const RgbImage no_contact = render_surface(cube_with_tool(false), settings);
  EXPECT_EQ(count_pixels(no_contact, blue), 0);
  EXPECT_EQ(no_contact.pixel(8 + 2 + 10, bar_row), (Rgb{255, 255, 255}));
  EXPECT_EQ(shaft, no_contact.pixel(static_cast<int>(view.project({0.25, 0.5, 1.15})[0]),
                                    static_cast<int>(view.project({0.25, 0.5, 1.15})[1])));

  // A force beyond full scale fills the bar in the overflow colour.
  SurfaceFrame strong = cube_with_tool(true);
  strong.force_n = {0.0, 0.0, 7.0};
  EXPECT_EQ(render_surface(strong, settings).pixel(8 + 2 + 100, bar_row), settings.force_overflow_colour);
}

TEST(PngRenderer, ToolInsideTheBodyIsHidden) {
  RenderSettings settings = small_settings(200, 200, {0, 0, 1}, {0, 1, 0});
  SurfaceFrame frame = cube(1.0);
  const RgbImage plain = render_surface(frame, settings);
  frame.has_tool = true;
  frame.tool_tip_m = {0.2, 0.2, 0.5};
  frame.tool_handle_m = {0.8, 0.8, 0.5};  // wholly inside the cube
  settings.force_bar_max_n = 0.0;
  EXPECT_EQ(render_surface(frame, settings).rgb, plain.rgb);
}

/// Decodes PNG bytes with libpng's simplified API; empty on failure.
RgbImage decode_png(const std::vector<std::uint8_t>& bytes) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  RgbImage image;
  if (png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()) == 0) return image;
  png.format = PNG_FORMAT_RGB;
  image.width = static_cast<int>(png.width);
  image.height = static_cast<int>(png.height);
  image.rgb.resize(std::size_t{3} * png.width * png.height);
  if (png_image_finish_read(&png, nullptr, image.rgb.data(), 0, nullptr) == 0) return {};
  return image;
}

TEST(PngRenderer, SameInputGivesSameBytesAndThePngDecodesToTheImage) {
  const TempDir dir;
  const SurfaceFrame frame = cube_with_tool(true);
  const RenderSettings settings;  // the default 1280 x 960 view
  render_png(dir.path() / "a.png", frame, settings);
  render_png(dir.path() / "b.png", cube_with_tool(true), settings);
  const std::string a = read_bytes(dir.path() / "a.png");
  ASSERT_GT(a.size(), 8U);
  EXPECT_EQ(a.substr(1, 3), "PNG");
  EXPECT_EQ(a, read_bytes(dir.path() / "b.png"));

  const RgbImage image = render_surface(frame, settings);
  const std::vector<std::uint8_t> bytes = encode_png(image);
  EXPECT_EQ(std::string(bytes.begin(), bytes.end()), a);
  const RgbImage decoded = decode_png(bytes);
  EXPECT_EQ(decoded.width, 1280);
  EXPECT_EQ(decoded.height, 960);
  EXPECT_EQ(decoded.rgb, image.rgb);
}

TEST(PngRenderer, RefusesNonFiniteInputAndBadSettings) {
  const TempDir dir;
  SurfaceFrame frame = cube(1.0);
  frame.positions_m[7] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)render_surface(frame), OutputError);
  EXPECT_THROW(render_png(dir.path() / "bad.png", frame), OutputError);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "bad.png"));
  frame = cube(1.0);
  frame.positions_m[0] = -std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)render_surface(frame), OutputError);
  frame = cube(1.0);
  frame.triangles[0] = 8;
  EXPECT_THROW((void)render_surface(frame), OutputError);
  frame = cube_with_tool(false);
  frame.tool_handle_m[2] = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)render_surface(frame), OutputError);
  frame = cube_with_tool(false);
  frame.tool_mode = 3;
  EXPECT_THROW((void)render_surface(frame), OutputError);

  const auto refused = [](void (*change)(RenderSettings&)) {
    RenderSettings settings;
    change(settings);
    EXPECT_THROW((void)render_surface(cube(1.0), settings), OutputError);
  };
  refused([](RenderSettings& s) { s.width = 0; });
  refused([](RenderSettings& s) { s.height = 20000; });
  refused([](RenderSettings& s) { s.supersampling = 0; });
  refused([](RenderSettings& s) { s.view_direction = {0, 0, 0}; });
  refused([](RenderSettings& s) { s.up = {std::numeric_limits<double>::quiet_NaN(), 0, 1}; });
  refused([](RenderSettings& s) { s.margin_fraction = 0.5; });
  refused([](RenderSettings& s) { s.fit_box_m = std::array<double, 6>{1, 0, 0, 0, 1, 1}; });
  refused([](RenderSettings& s) { s.ambient = 1.5; });
  refused([](RenderSettings& s) { s.force_scale_m_per_n = std::numeric_limits<double>::infinity(); });
  EXPECT_THROW((void)encode_png(RgbImage{2, 2, std::vector<std::uint8_t>(11)}), OutputError);
}

TEST(PngRenderer, FitsAFixedBoxAndFallsBackWhenUpIsAlongTheView) {
  const SurfaceFrame frame = cube(1.0);
  RenderSettings settings = small_settings(200, 100, {0, 0, 1}, {0, 0, 1});  // up along the view: +y instead
  const OrthographicView view = fit_view(frame, settings);
  EXPECT_EQ(view.up, (std::array<double, 3>{0, 1, 0}));
  EXPECT_EQ(view.right, (std::array<double, 3>{1, 0, 0}));
  EXPECT_EQ(view.toward_viewer, (std::array<double, 3>{0, 0, 1}));
  EXPECT_NEAR(view.metres_per_pixel, 1.0 / 90.0, 1e-15);  // the height less 5 % margins

  settings.fit_box_m = std::array<double, 6>{-1, -1, -1, 3, 3, 3};  // a fixed camera for a sequence
  const OrthographicView fixed = fit_view(frame, settings);
  EXPECT_NEAR(fixed.metres_per_pixel, 4.0 / 90.0, 1e-15);
  EXPECT_EQ(fixed.centre_m, (std::array<double, 3>{1, 1, 1}));
  const double covered = static_cast<double>(covered_pixels(render_surface(frame, settings), settings));
  EXPECT_NEAR(covered, 22.5 * 22.5, 4 * 23.5);
}

}  // namespace
}  // namespace tissue::host
