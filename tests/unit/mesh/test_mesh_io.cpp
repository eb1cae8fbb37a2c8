// Mesh readers: every kind of bad input is refused naming file, line and element; inverted tets
// are repaired with a warning; the Vega reference meshes and the project's own meshes load with
// the documented counts; the bar/beam files equal the C++ box generator.
#include "core/mesh/box_mesh.hpp"
#include "core/mesh/mesh_io.hpp"
#include "reference_meshes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace tissue {
namespace {

const std::filesystem::path MESH_DIR = TISSUE_MESH_DIR;
const std::filesystem::path VEGA_DIR = test_data::vega_reference_dir();

/// Runs `load`, expects a MeshError, and checks its line, its 0-based element and that its
/// message contains "<source>:<line>: " and every one of `fragments`.
void expect_refused(const std::function<void()>& load, const std::string& source, int line, int element,
                    const std::vector<std::string>& fragments) {
  try {
    load();
    ADD_FAILURE() << "no MeshError (expected line " << line << ")";
  } catch (const MeshError& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.line(), line) << message;
    EXPECT_EQ(error.element(), element) << message;
    EXPECT_EQ(error.file(), source) << message;
    const std::string where = line > 0 ? source + ":" + std::to_string(line) + ": " : source + ": ";
    EXPECT_EQ(message.rfind(where, 0), 0U) << "message does not start with '" << where << "': " << message;
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos) << "'" << fragment << "' not in: " << message;
    }
  }
}

void expect_veg_refused(const std::string& text, int line, int element, const std::vector<std::string>& fragments) {
  expect_refused([&] { parse_veg(text, "test.veg"); }, "test.veg", line, element, fragments);
}

void expect_gmsh_refused(const std::string& text, int line, int element, const std::vector<std::string>& fragments) {
  expect_refused([&] { parse_gmsh(text, "test.msh"); }, "test.msh", line, element, fragments);
}

double total_volume(const TetMesh& mesh) {
  double volume_m3 = 0.0;
  for (const Tet& tet : mesh.tets) {
    volume_m3 += signed_tet_volume(mesh.rest_positions_m[tet[0]], mesh.rest_positions_m[tet[1]],
                                   mesh.rest_positions_m[tet[2]], mesh.rest_positions_m[tet[3]]);
  }
  return volume_m3;
}

void expect_all_positive(const TetMesh& mesh) {
  for (int t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    ASSERT_GT(signed_tet_volume(mesh.rest_positions_m[tet[0]], mesh.rest_positions_m[tet[1]],
                                mesh.rest_positions_m[tet[2]], mesh.rest_positions_m[tet[3]]),
              0.0)
        << "tet " << t;
  }
}

/// A temporary directory removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_path = std::filesystem::temp_directory_path() /
             (std::string("tissue_mesh_") + info->test_suite_name() + "_" + info->name());
    std::filesystem::remove_all(m_path);
    std::filesystem::create_directories(m_path);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(m_path, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::filesystem::path path = m_path / name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  [[nodiscard]] const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

// Two tets sharing the face (2, 3, 4): vertices 1-4 form a positive unit corner tet, vertex 5
// lies beyond the face 2-3-4. Line numbers are referred to in the tests below.
const std::string TWO_TETS_VEG =
    "# two tets\n"      // 1
    "*VERTICES\n"       // 2
    "5 3 0 0\n"         // 3
    "1 0 0 0\n"         // 4
    "2 1 0 0\n"         // 5
    "3 0 1 0\n"         // 6
    "4 0 0 1\n"         // 7
    "5 1 1 1\n"         // 8
    "\n"                // 9
    "*ELEMENTS\n"       // 10
    "TET\n"             // 11
    "2 4 0\n"           // 12
    "1 1 2 3 4\n"       // 13
    "2 2 3 4 5\n"       // 14
    "\n"                // 15
    "*MATERIAL BODY\n"  // 16
    "ENU, 1000, 1e6, 0.45\n"
    "*REGION\n"
    "allElements, BODY\n";

std::string replace_line(const std::string& text, int line, const std::string& replacement) {
  std::string result;
  int number = 1;
  std::size_t begin = 0;
  while (begin < text.size()) {
    std::size_t end = text.find('\n', begin);
    end = end == std::string::npos ? text.size() : end + 1;
    result += number == line ? replacement + "\n" : text.substr(begin, end - begin);
    begin = end;
    ++number;
  }
  return result;
}

// ---------------------------------------------------------------------------------------------
// Vega .veg

TEST(VegReader, ReadsVerticesAndTetsSkippingOtherSections) {
  MeshWarnings warnings;
  const TetMesh mesh = parse_veg(TWO_TETS_VEG, "test.veg", &warnings);
  ASSERT_EQ(mesh.vertex_count(), 5);
  ASSERT_EQ(mesh.tet_count(), 2);
  EXPECT_EQ(mesh.tets[0], (Tet{0, 1, 2, 3}));
  EXPECT_EQ(mesh.tets[1], (Tet{1, 2, 3, 4}));
  EXPECT_EQ(mesh.rest_positions_m[4], Eigen::Vector3d(1, 1, 1));
  EXPECT_TRUE(warnings.messages.empty());
  expect_all_positive(mesh);
  EXPECT_NEAR(total_volume(mesh), 1.0 / 6.0 + 1.0 / 3.0, 1e-15);
}

TEST(VegReader, InvertedTetIsReorientedWithWarning) {
  // Element 2 written with its last two vertices the other way round: negative volume.
  const std::string text = replace_line(TWO_TETS_VEG, 14, "2 2 3 5 4");
  MeshWarnings warnings;
  const TetMesh mesh = parse_veg(text, "test.veg", &warnings);
  ASSERT_EQ(warnings.messages.size(), 1U);
  const std::string& warning = warnings.messages[0];
  EXPECT_EQ(warning.rfind("test.veg:14: element 2: ", 0), 0U) << warning;
  EXPECT_NE(warning.find("inverted"), std::string::npos) << warning;
  EXPECT_EQ(mesh.tets[1], (Tet{1, 2, 3, 4}));  // local vertices 2 and 3 swapped
  expect_all_positive(mesh);
  // Without a warnings sink the repair still happens.
  EXPECT_EQ(parse_veg(text, "test.veg").tets[1], (Tet{1, 2, 3, 4}));
}

TEST(VegReader, RefusesOutOfRangeVertexIndex) {
  expect_veg_refused(replace_line(TWO_TETS_VEG, 14, "2 2 3 6 4"), 14, 1, {"element 2", "6", "out of range [1, 5]"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 13, "1 0 2 3 4"), 13, 0, {"element 1", "0", "out of range"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 13, "1 -3 2 3 4"), 13, 0, {"element 1", "-3", "out of range"});
}

TEST(VegReader, RefusesNonFiniteCoordinates) {
  expect_veg_refused(replace_line(TWO_TETS_VEG, 6, "3 0 nan 0"), 6, -1, {"vertex 3", "not finite"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 7, "4 0 0 inf"), 7, -1, {"vertex 4", "not finite"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 8, "5 1e999 1 1"), 8, -1, {"vertex 5", "not finite"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 8, "5 -1e999 1 1"), 8, -1, {"vertex 5", "not finite"});
  // Underflow is harmless: read as 0.
  EXPECT_EQ(parse_veg(replace_line(TWO_TETS_VEG, 8, "5 1 1 1e-999"), "test.veg").rest_positions_m[4].z(), 0.0);
}

// Found by fuzzing (issue 44): a coordinate of 1e308 was taken, and the surface tree's bounds then
// overflowed (a bad free inside Bullet's btDbvt).
TEST(VegReader, RefusesCoordinatesBeyondTheDeclaredMaximum) {
  expect_veg_refused(replace_line(TWO_TETS_VEG, 8, "5 1e308 1 1"), 8, -1, {"vertex 5", "MAX_ABS_COORDINATE"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 5, "2 1 -2e6 0"), 5, -1, {"vertex 2", "MAX_ABS_COORDINATE"});
  // At the limit: the two tets scaled by 1e6 (a 1 m body in micrometres) are taken.
  std::string scaled = replace_line(TWO_TETS_VEG, 5, "2 1e6 0 0");
  scaled = replace_line(scaled, 6, "3 0 1e6 0");
  scaled = replace_line(scaled, 7, "4 0 0 1e6");
  scaled = replace_line(scaled, 8, "5 1e6 1e6 1e6");
  EXPECT_NO_THROW(parse_veg(scaled, "test.veg"));
}

// Found by fuzzing (issue 44): three tets on one face were taken and then refused by the tissue
// (its adjacency), with no file or line.
TEST(VegReader, RefusesAFaceSharedByThreeTets) {
  std::string text = replace_line(TWO_TETS_VEG, 14, "2 2 3 4 5\n3 2 3 4 6");
  text = replace_line(text, 12, "3 4 0");
  text = replace_line(text, 8, "5 1 1 1\n6 2 1 1");  // the third tet is on line 16 now
  text = replace_line(text, 3, "6 3 0 0");
  expect_veg_refused(text, 16, 2, {"shared by more than two tets", "overlapping"});
}

TEST(VegReader, RefusesNonNumericTokens) {
  expect_veg_refused(replace_line(TWO_TETS_VEG, 5, "2 1 zero 0"), 5, -1, {"vertex 2", "'zero' is not a number"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 5, "2 1 0.5x 0"), 5, -1, {"vertex 2", "'0.5x'"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 14, "2 2 3 five 4"), 14, 1, {"element 2", "'five' is not an integer"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 14, "2 2 3 5.0 4"), 14, 1, {"element 2", "'5.0'"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 3, "five 3 0 0"), 3, -1, {"*VERTICES header", "'five'"});
}

TEST(VegReader, RefusesWrongColumnCountsAndIds) {
  expect_veg_refused(replace_line(TWO_TETS_VEG, 14, "2 2 3 5"), 14, 1, {"element 2", "expected 5 values"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 14, "2 2 3 5 4 1"), 14, 1, {"element 2", "expected 5 values"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 6, "3 0 1"), 6, -1, {"vertex 3", "expected 4 values"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 6, "7 0 1 0"), 6, -1, {"vertex 3", "id 7 out of sequence"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 14, "9 2 3 5 4"), 14, 1, {"element 2", "id 9 out of sequence"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 11, "CUBIC"), 11, -1, {"'CUBIC' is not supported"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 12, "2 8 0"), 12, -1, {"*ELEMENTS header", "expected 4"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 3, "5 2 0 0"), 3, -1, {"*VERTICES header", "expected 3"});
}

TEST(VegReader, RefusesMissingSections) {
  // Drop *ELEMENTS and everything after it.
  const std::string no_elements = TWO_TETS_VEG.substr(0, TWO_TETS_VEG.find("*ELEMENTS"));
  expect_veg_refused(no_elements, 0, -1, {"missing *ELEMENTS section"});
  std::string no_vertices = TWO_TETS_VEG;
  no_vertices.erase(no_vertices.find("*VERTICES"), no_vertices.find("*ELEMENTS") - no_vertices.find("*VERTICES"));
  expect_veg_refused(no_vertices, 0, -1, {"missing *VERTICES section"});
  expect_veg_refused("", 0, -1, {"missing *VERTICES"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 11, ""), 12, -1, {"'2' is not supported"});
}

TEST(VegReader, RefusesWrongCountsAndTruncation) {
  // Header promises 6 vertices; the 6th "line" is the *ELEMENTS keyword on line 10.
  expect_veg_refused(replace_line(TWO_TETS_VEG, 3, "6 3 0 0"), 10, -1, {"*VERTICES", "truncated", "expected 6"});
  // Header promises 4 vertices; line 8 is one too many.
  expect_veg_refused(replace_line(TWO_TETS_VEG, 3, "4 3 0 0"), 8, -1, {"*VERTICES", "more lines than the count 4"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 12, "3 4 0"), 16, -1, {"*ELEMENTS", "truncated", "expected 3"});
  expect_veg_refused(replace_line(TWO_TETS_VEG, 12, "1 4 0"), 14, -1, {"*ELEMENTS", "more lines than the count 1"});
  // File cut after the first element: truncation is reported at the last line.
  const std::string cut = TWO_TETS_VEG.substr(0, TWO_TETS_VEG.find("2 2 3 4 5"));
  expect_veg_refused(cut, 13, -1, {"*ELEMENTS", "truncated", "expected 2 elements, found 1"});
  // Cut in the middle of a vertex line.
  const std::string cut_vertex = TWO_TETS_VEG.substr(0, TWO_TETS_VEG.find("3 0 1 0") + 4);
  expect_veg_refused(cut_vertex, 6, -1, {"vertex 3", "expected 4 values"});
  // A stray data line before any section.
  expect_veg_refused("1 2 3\n" + TWO_TETS_VEG, 1, -1, {"expected a *SECTION"});
}

TEST(VegReader, RefusesZeroVolumeTets) {
  expect_veg_refused(replace_line(TWO_TETS_VEG, 14, "2 2 3 2 4"), 14, 1, {"element 2", "zero-volume", "repeated"});
  // Vertex 5 moved into the plane x + y + z = 1 of vertices 2, 3, 4.
  expect_veg_refused(replace_line(TWO_TETS_VEG, 8, "5 0.5 0.25 0.25"), 14, 1, {"element 2", "zero-volume"});
  // The threshold is relative, 1e-12 * diag^3 = 5.2e-12 here (diagonal sqrt(3)): a lift of
  // 1e-12 gives a volume of 1.7e-13 (refused), a lift of 1e-9 gives 1.7e-10 (accepted).
  expect_veg_refused(replace_line(TWO_TETS_VEG, 8, "5 0.5 0.25 0.250000000001"), 14, 1, {"element 2", "zero-volume"});
  EXPECT_NO_THROW(parse_veg(replace_line(TWO_TETS_VEG, 8, "5 0.5 0.25 0.250000001"), "test.veg"));
}

TEST(VegReader, RefusesDuplicateTetsNamingBoth) {
  std::string text = replace_line(TWO_TETS_VEG, 12, "3 4 0");
  text = replace_line(text, 14, "2 2 3 4 5\n3 3 1 4 2");  // same vertex set as element 1
  expect_veg_refused(text, 15, 2, {"element 3", "duplicate of element 1", "line 13"});
}

TEST(VegReader, RefusesMissingFile) {
  expect_refused([] { read_veg("/nonexistent/dir/mesh.veg"); }, "/nonexistent/dir/mesh.veg", 0, -1, {"cannot open"});
}

TEST(VegReader, ReadsVegaReferenceMeshes) {
  TISSUE_SKIP_WITHOUT_VEGA_MESHES();
  struct Reference {
    const char* file;
    int vertices;
    int tets;
  };
  const Reference references[] = {
      {"simpleBridge/simpleBridge-ic_128_0.15_.1.veg", 4000, 12827},
      {"turtle/turtle-volumetric-homogeneous.veg", 347, 1185},
      {"comb/comb.tet.veg", 1623, 5844},
      {"beam3/beam3_tet.veg", 208, 450},
  };
  for (const Reference& reference : references) {
    SCOPED_TRACE(reference.file);
    MeshWarnings warnings;
    const TetMesh mesh = read_mesh(VEGA_DIR / reference.file, &warnings);
    EXPECT_EQ(mesh.vertex_count(), reference.vertices);
    EXPECT_EQ(mesh.tet_count(), reference.tets);
    expect_all_positive(mesh);
    for (const std::string& message : warnings.messages) {
      EXPECT_NE(message.find(reference.file), std::string::npos) << message;
    }
  }
  // The heterogeneous turtle's two regions list their elements in *INCLUDE'd files, not shipped
  // with it: refused, saying so, rather than read without its regions.
  expect_refused([] { read_mesh(VEGA_DIR / "turtle/turtle-volumetric-heterogeneous.veg"); },
                 (VEGA_DIR / "turtle/turtle-volumetric-heterogeneous.veg").string(), 1545, -1,
                 {"*SET backshell: its elements are in an *INCLUDE'd file, which is not read"});
  // The bridge's file gives every element its material (*REGION allElements): E = 1e7 Pa.
  const TetMesh bridge_regions = read_veg(VEGA_DIR / "simpleBridge/simpleBridge-ic_128_0.15_.1.veg");
  ASSERT_EQ(bridge_regions.regions.size(), 1u);
  ASSERT_TRUE(bridge_regions.regions[0].material.has_value());
  EXPECT_EQ(bridge_regions.regions[0].material->young_modulus_pa, 1e7);
  // The first vertex of the bridge, as written in the file.
  const TetMesh bridge = read_veg(VEGA_DIR / "simpleBridge/simpleBridge-ic_128_0.15_.1.veg");
  EXPECT_EQ(bridge.rest_positions_m[0], Eigen::Vector3d(-6.75193, 1.76055, 0.961333));
}

TEST(BouReader, ReadsVegaFixedVertices) {
  TISSUE_SKIP_WITHOUT_VEGA_MESHES();
  const std::vector<int> fixed = read_bou(VEGA_DIR / "simpleBridge/simpleBridge.bou", 4000);
  ASSERT_FALSE(fixed.empty());
  EXPECT_TRUE(std::is_sorted(fixed.begin(), fixed.end()));
  EXPECT_EQ(std::adjacent_find(fixed.begin(), fixed.end()), fixed.end());
  EXPECT_GE(fixed.front(), 0);
  EXPECT_LT(fixed.back(), 4000);
  // The file starts "249,255,281," (1-indexed).
  EXPECT_EQ(fixed[0], 248);
  EXPECT_EQ(fixed[1], 254);
}

TEST(BouReader, ParsesSeparatorsAndRefusesBadIds) {
  const TempDir dir;
  const auto good = dir.write("good.bou", "# fixed\n5, 3,\n3 1\n");
  EXPECT_EQ(read_bou(good, 5), (std::vector<int>{0, 2, 4}));
  const auto high = dir.write("high.bou", "1,2,\n3,6\n");
  expect_refused([&] { read_bou(high, 5); }, high.string(), 2, -1, {"vertex 6 out of range [1, 5]"});
  const auto zero = dir.write("zero.bou", "0\n");
  expect_refused([&] { read_bou(zero, 5); }, zero.string(), 1, -1, {"vertex 0 out of range"});
  const auto text = dir.write("text.bou", "1,2\nthree\n");
  expect_refused([&] { read_bou(text, 5); }, text.string(), 2, -1, {"'three' is not an integer"});
}

// ---------------------------------------------------------------------------------------------
// TetGen .node / .ele

const std::string k_node_0_based =
    "# TetGen points\n"       // 1
    "5 3 1 1\n"               // 2
    "0 0 0 0  7.5 1\n"        // 3
    "1 1 0 0  7.5 1\n"        // 4
    "2 0 1 0  7.5 0   # c\n"  // 5
    "3 0 0 1  7.5 1\n"        // 6
    "4 1 1 1  7.5 1\n";       // 7
const std::string k_ele_0_based =
    "2 4 1\n"            // 1
    "  0 0 1 2 3 1.0\n"  // 2
    "  1 1 2 3 4 2.0\n"  // 3
    "# Generated by tetgen\n";

TEST(TetgenReader, ReadsZeroBasedWithAttributesAndMarkers) {
  const TempDir dir;
  (void)dir.write("box.1.node", k_node_0_based);
  const auto ele = dir.write("box.1.ele", k_ele_0_based);
  for (const auto& path : {dir.path() / "box.1.node", ele, dir.path() / "box.1"}) {
    SCOPED_TRACE(path.string());
    MeshWarnings warnings;
    const TetMesh mesh = path.extension() == ".1" ? read_tetgen(path, &warnings) : read_mesh(path, &warnings);
    ASSERT_EQ(mesh.vertex_count(), 5);
    ASSERT_EQ(mesh.tet_count(), 2);
    EXPECT_EQ(mesh.tets[1], (Tet{1, 2, 3, 4}));
    EXPECT_TRUE(warnings.messages.empty());
  }
}

TEST(TetgenReader, ReadsOneBasedAndTenNodeTets) {
  const TempDir dir;
  (void)dir.write("m.node", "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n");
  // Inverted (3 and 4 swapped) and quadratic: the six edge nodes are read and ignored.
  const auto ele = dir.write("m.ele", "1 10 0\n1 1 2 4 3 1 2 3 4 1 2\n");
  MeshWarnings warnings;
  const TetMesh mesh = read_tetgen(ele, &warnings);
  EXPECT_EQ(mesh.tets[0], (Tet{0, 1, 2, 3}));
  ASSERT_EQ(warnings.messages.size(), 1U);
  EXPECT_EQ(warnings.messages[0].rfind(ele.string() + ":2: element 1: inverted", 0), 0U) << warnings.messages[0];
}

TEST(TetgenReader, RefusesBadInputNamingTheRightFile) {
  const TempDir dir;
  const auto node = dir.write("a.node", k_node_0_based);
  const auto ele = dir.write("a.ele", replace_line(k_ele_0_based, 3, "  1 1 2 5 3 2.0"));
  expect_refused([&] { read_tetgen(node); }, ele.string(), 3, 1, {"element 1", "vertex index 5 out of range [0, 4]"});

  (void)dir.write("b.node", replace_line(k_node_0_based, 2, "6 3 1 1"));
  (void)dir.write("b.ele", k_ele_0_based);
  expect_refused([&] { read_tetgen(dir.path() / "b.node"); }, (dir.path() / "b.node").string(), 7, -1,
                 {"truncated", "expected 6 points, found 5"});

  (void)dir.write("c.node", replace_line(k_node_0_based, 4, "1 1 nan 0  7.5 1"));
  (void)dir.write("c.ele", k_ele_0_based);
  expect_refused([&] { read_tetgen(dir.path() / "c.node"); }, (dir.path() / "c.node").string(), 4, -1,
                 {"point 1", "not finite"});

  (void)dir.write("d.node", k_node_0_based);
  (void)dir.write("d.ele", replace_line(k_ele_0_based, 3, "  1 1 2 4 3"));
  expect_refused([&] { read_tetgen(dir.path() / "d.ele"); }, (dir.path() / "d.ele").string(), 3, 1,
                 {"element 1", "expected 6 values"});

  (void)dir.write("e.node", replace_line(k_node_0_based, 3, "2 0 0 0  7.5 1"));
  (void)dir.write("e.ele", k_ele_0_based);
  expect_refused([&] { read_tetgen(dir.path() / "e.node"); }, (dir.path() / "e.node").string(), 3, -1,
                 {"numbered 0 or 1"});

  (void)dir.write("f.node", k_node_0_based);
  expect_refused([&] { read_tetgen(dir.path() / "f.node"); }, (dir.path() / "f.ele").string(), 0, -1, {"cannot open"});
}

// ---------------------------------------------------------------------------------------------
// Gmsh .msh 4.1

// Node tags 10, 20, 30, 40 (one block) and 7 (a second block): non-contiguous. Elements: a
// point and a triangle that must be ignored, two tets (tags 100 and 200).
const std::string TWO_TETS_MSH =
    "$MeshFormat\n"        // 1
    "4.1 0 8\n"            // 2
    "$EndMeshFormat\n"     // 3
    "$PhysicalNames\n"     // 4
    "1\n"                  // 5
    "3 1 \"body\"\n"       // 6
    "$EndPhysicalNames\n"  // 7
    "$Nodes\n"             // 8
    "2 5 7 40\n"           // 9
    "3 1 0 4\n"            // 10
    "10\n"                 // 11
    "20\n"                 // 12
    "30\n"                 // 13
    "40\n"                 // 14
    "0 0 0\n"              // 15
    "1 0 0\n"              // 16
    "0 1 0\n"              // 17
    "0 0 1\n"              // 18
    "2 5 1 1\n"            // 19  (parametric: x y z u v)
    "7\n"                  // 20
    "1 1 1 0.25 0.75\n"    // 21
    "$EndNodes\n"          // 22
    "$Elements\n"          // 23
    "3 4 1 200\n"          // 24
    "0 1 15 1\n"           // 25
    "1 10\n"               // 26
    "2 5 2 1\n"            // 27
    "2 20 30 40\n"         // 28
    "3 1 4 2\n"            // 29
    "100 10 20 30 40\n"    // 30
    "200 20 30 40 7\n"     // 31
    "$EndElements\n";      // 32

TEST(GmshReader, MapsNodeTagsAndKeepsOnlyTets) {
  MeshWarnings warnings;
  const TetMesh mesh = parse_gmsh(TWO_TETS_MSH, "test.msh", &warnings);
  ASSERT_EQ(mesh.vertex_count(), 5);
  ASSERT_EQ(mesh.tet_count(), 2);
  EXPECT_EQ(mesh.tets[0], (Tet{0, 1, 2, 3}));
  EXPECT_EQ(mesh.tets[1], (Tet{1, 2, 3, 4}));
  EXPECT_EQ(mesh.rest_positions_m[4], Eigen::Vector3d(1, 1, 1));
  EXPECT_TRUE(warnings.messages.empty());
}

TEST(GmshReader, InvertedTetWarningUsesTheElementTag) {
  MeshWarnings warnings;
  const TetMesh mesh = parse_gmsh(replace_line(TWO_TETS_MSH, 31, "200 20 30 7 40"), "test.msh", &warnings);
  ASSERT_EQ(warnings.messages.size(), 1U);
  EXPECT_EQ(warnings.messages[0].rfind("test.msh:31: element 200: inverted", 0), 0U) << warnings.messages[0];
  expect_all_positive(mesh);
}

TEST(GmshReader, RefusesWrongFormat) {
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 2, "2.2 0 8"), 2, -1, {"version 2.2 is not supported"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 2, "4.1 1 8"), 2, -1, {"binary"});
  expect_gmsh_refused(TWO_TETS_MSH.substr(TWO_TETS_MSH.find("$PhysicalNames")), 1, -1, {"missing $MeshFormat"});
  expect_gmsh_refused("", 0, -1, {"missing $MeshFormat"});
}

TEST(GmshReader, RefusesMissingSections) {
  std::string no_nodes = TWO_TETS_MSH;
  no_nodes.erase(no_nodes.find("$Nodes"), no_nodes.find("$Elements") - no_nodes.find("$Nodes"));
  expect_gmsh_refused(no_nodes, 8, -1, {"$Elements before $Nodes"});
  const std::string only_format = TWO_TETS_MSH.substr(0, TWO_TETS_MSH.find("$Nodes"));
  expect_gmsh_refused(only_format, 0, -1, {"missing $Nodes section"});
  const std::string no_elements = TWO_TETS_MSH.substr(0, TWO_TETS_MSH.find("$Elements"));
  expect_gmsh_refused(no_elements, 0, -1, {"missing $Elements section"});
  expect_gmsh_refused(TWO_TETS_MSH.substr(0, TWO_TETS_MSH.find("$EndPhysicalNames")), 6, -1,
                      {"$PhysicalNames: missing $EndPhysicalNames"});
}

TEST(GmshReader, RefusesUnknownNodeTagsAndBadNumbers) {
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 31, "200 20 30 8 40"), 31, 1,
                      {"element 200", "node tag 8 is not in $Nodes"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 17, "0 nan 0"), 17, -1, {"node 30", "not finite"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 30, "100 10 20 x 40"), 30, 0, {"element 100", "'x'"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 30, "100 10 20 30"), 30, 0, {"element 100", "expected 5"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 12, "10"), 12, -1, {"node 10", "defined twice"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 21, "1 1 1 0.25"), 21, -1, {"node 7", "expected 5 values"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 31, "200 20 30 20 40"), 31, 1, {"element 200", "zero-volume"});
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 31, "200 40 10 30 20"), 31, 1,
                      {"element 200", "duplicate of element 100", "line 30"});
}

TEST(GmshReader, RefusesWrongCountsAndTruncation) {
  // Header says 6 nodes, blocks hold 5.
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 9, "2 6 7 40"), 21, -1, {"$Nodes", "says 6 nodes"});
  // Block says 5 nodes: tag lines run into the coordinates, then the section ends early.
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 10, "3 1 0 5"), 15, -1, {"expected 1 values"});
  // Element block promises 3 tets.
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 29, "3 1 4 3"), 32, -1, {"$Elements", "truncated"});
  // Header says 5 elements.
  expect_gmsh_refused(replace_line(TWO_TETS_MSH, 24, "3 5 1 200"), 31, -1, {"$Elements", "says 5 elements"});
  // File cut inside $Elements.
  const std::string cut = TWO_TETS_MSH.substr(0, TWO_TETS_MSH.find("200 20 30 40 7"));
  expect_gmsh_refused(cut, 30, -1, {"$Elements", "truncated"});
  // No tets at all.
  std::string no_tets = replace_line(TWO_TETS_MSH, 24, "2 2 1 200");
  no_tets = replace_line(no_tets, 29, "");
  no_tets = replace_line(no_tets, 30, "");
  no_tets = replace_line(no_tets, 31, "");
  expect_gmsh_refused(no_tets, 32, -1, {"no 4-node tetrahedra"});
}

TEST(MeshReader, RefusesUnknownExtension) {
  expect_refused([] { read_mesh("specimen.stl"); }, "specimen.stl", 0, -1, {"unknown mesh format '.stl'"});
}

TEST(ValidateTets, ChecksMeshesBuiltInCode) {
  TetMesh mesh = make_box_mesh(1, 1, 1, 1.0);
  MeshWarnings warnings;
  std::swap(mesh.tets[2][2], mesh.tets[2][3]);
  validate_tets(mesh, "code", {}, {}, 0, &warnings);
  ASSERT_EQ(warnings.messages.size(), 1U);
  EXPECT_EQ(warnings.messages[0].rfind("code: element 2: inverted", 0), 0U) << warnings.messages[0];
  expect_all_positive(mesh);

  mesh.tets[4][0] = 8;
  expect_refused([&] { validate_tets(mesh, "code", {}, {}, 1, nullptr); }, "code", 0, 4,
                 {"element 5", "vertex index 9 out of range [1, 8]"});
  mesh = make_box_mesh(1, 1, 1, 1.0);
  mesh.rest_positions_m[3].y() = std::numeric_limits<double>::quiet_NaN();
  expect_refused(
      [&] {
        validate_tets(mesh, "code", {11, 12, 13, 14, 15, 16, 17, 18}, {}, 1, nullptr);
      },
      "code", 14, -1, {"vertex 4", "not finite"});
}

TEST(ValidateTets, SummarisesManyInvertedTetsAndWarnsOfUnusedVertices) {
  TetMesh mesh = make_box_mesh(6, 5, 1, 0.01);  // 150 tets
  for (Tet& tet : mesh.tets) {
    std::swap(tet[2], tet[3]);
  }
  mesh.rest_positions_m.emplace_back(1.0, 1.0, 1.0);  // used by no tet
  MeshWarnings warnings;
  validate_tets(mesh, "code", {}, {}, 0, &warnings);
  expect_all_positive(mesh);
  EXPECT_EQ(mesh.tets, make_box_mesh(6, 5, 1, 0.01).tets);
  ASSERT_EQ(warnings.messages.size(), 102U);  // 100 single ones, a summary, the unused vertex
  EXPECT_EQ(warnings.messages[99].rfind("code: element 99: inverted", 0), 0U) << warnings.messages[99];
  EXPECT_NE(warnings.messages[100].find("50 more inverted tets re-oriented (150 in all)"), std::string::npos)
      << warnings.messages[100];
  EXPECT_NE(warnings.messages[101].find("1 vertices are not used by any tet (first: vertex 84)"), std::string::npos)
      << warnings.messages[101];
}

// ---------------------------------------------------------------------------------------------
// The project's own meshes (meshes/README.md)

void expect_same_mesh(const TetMesh& a, const TetMesh& b, double tolerance_m) {
  ASSERT_EQ(a.vertex_count(), b.vertex_count());
  ASSERT_EQ(a.tet_count(), b.tet_count());
  for (int v = 0; v < a.vertex_count(); ++v) {
    ASSERT_LE((a.rest_positions_m[v] - b.rest_positions_m[v]).lpNorm<Eigen::Infinity>(), tolerance_m) << "vertex " << v;
  }
  for (int t = 0; t < a.tet_count(); ++t) {
    ASSERT_EQ(a.tets[t], b.tets[t]) << "tet " << t;
  }
}

TEST(ProjectMeshes, BarMatchesBoxGenerator) {
  MeshWarnings warnings;
  const TetMesh bar = read_mesh(MESH_DIR / "bar_40x8x8.veg", &warnings);
  EXPECT_EQ(bar.vertex_count(), 3321);
  EXPECT_EQ(bar.tet_count(), 12800);
  EXPECT_TRUE(warnings.messages.empty());
  expect_same_mesh(bar, make_box_mesh(40, 8, 8, 0.01), 1e-12);
  EXPECT_NEAR(total_volume(bar), 0.4 * 0.08 * 0.08, 1e-15);
  EXPECT_EQ(bar.rest_positions_m[1], Eigen::Vector3d(0.01, 0, 0));  // x fastest
  EXPECT_EQ(bar.rest_positions_m[41], Eigen::Vector3d(0, 0.01, 0));
}

TEST(ProjectMeshes, BeamMatchesBoxGenerator) {
  MeshWarnings warnings;
  const TetMesh beam = read_mesh(MESH_DIR / "beam_10x2x2.veg", &warnings);
  EXPECT_EQ(beam.vertex_count(), 99);
  EXPECT_EQ(beam.tet_count(), 200);
  EXPECT_TRUE(warnings.messages.empty());
  expect_same_mesh(beam, make_box_mesh(10, 2, 2, 0.01), 1e-12);
}

TEST(ProjectMeshes, FrogMshAndVegAgree) {
  MeshWarnings msh_warnings;
  MeshWarnings veg_warnings;
  const TetMesh from_msh = read_mesh(MESH_DIR / "frog.msh", &msh_warnings);
  const TetMesh from_veg = read_mesh(MESH_DIR / "frog.veg", &veg_warnings);
  EXPECT_EQ(from_msh.vertex_count(), 817);
  EXPECT_EQ(from_msh.tet_count(), 2450);
  // Within 15% of the dissertation's frog (826 vertices, 2301 tets).
  EXPECT_NEAR(from_msh.vertex_count(), 826, 0.15 * 826);
  EXPECT_NEAR(from_msh.tet_count(), 2301, 0.15 * 2301);
  EXPECT_TRUE(msh_warnings.messages.empty());
  EXPECT_TRUE(veg_warnings.messages.empty());
  expect_same_mesh(from_msh, from_veg, 0.0);
  // About 0.12 m long (x), in metres.
  double min_x = 1e9;
  double max_x = -1e9;
  for (const auto& p : from_msh.rest_positions_m) {
    min_x = std::min(min_x, p.x());
    max_x = std::max(max_x, p.x());
  }
  EXPECT_NEAR(max_x - min_x, 0.12, 0.015);
}

}  // namespace
}  // namespace tissue
