// Mesh readers' common path: the helpers they share (mesh_io_detail.hpp), the checks every reader
// applies and the dispatch on the extension. Each reader (veg_reader.cpp, tetgen_reader.cpp,
// gmsh_reader.cpp) first collects what the file says into a RawMesh (vertex numbers as written in
// the file), then finish() maps the numbers to 0-based indices and validates, so every format
// refuses bad input with the same messages.
#include "core/mesh/mesh_io.hpp"

#include "core/mesh/mesh_io_detail.hpp"
#include "core/mesh/topology.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>
#include <utility>

namespace tissue {
namespace mesh_io_detail {

std::string location(const std::string& source, int line) {
  if (line > 0) {
    return source + ":" + std::to_string(line);
  }
  return source;
}

[[noreturn]] void fail(const std::string& source, int line, int element, const std::string& what) {
  throw MeshError(location(source, line) + ": " + what, source, line, element);
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    fail(path.string(), 0, -1, "cannot open file");
  }
  // Read in blocks up to the limit, so that a device or a pipe that never ends (/dev/zero) is refused too.
  std::string text;
  std::array<char, 1 << 16> block{};
  while (in.read(block.data(), block.size()) || in.gcount() > 0) {
    const auto got = static_cast<std::size_t>(in.gcount());
    if (text.size() + got > MAX_MESH_FILE_BYTES) {
      fail(path.string(), 0, -1, "larger than MAX_MESH_FILE_BYTES (" + std::to_string(MAX_MESH_FILE_BYTES) + " bytes)");
    }
    text.append(block.data(), got);
  }
  if (in.bad()) {
    fail(path.string(), 0, -1, "read error");
  }
  return text;
}

std::string to_upper(std::string_view text) {
  std::string result(text);
  for (char& c : result) {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return result;
}

std::optional<std::int64_t> parse_int(std::string_view token) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
  }
  std::int64_t value = 0;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (token.empty() || ec != std::errc() || ptr != end) {
    return std::nullopt;
  }
  return value;
}

std::optional<double> parse_double(std::string_view token) {
  if (!token.empty() && token.front() == '+') {
    token.remove_prefix(1);
  }
  double value = 0.0;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (token.empty() || ptr != end) {
    return std::nullopt;
  }
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves `value` untouched here, so tell overflow (reported as a non-finite
    // coordinate) from harmless underflow (read as 0) by the sign of the exponent, or, without
    // one, by whether the mantissa is below 1.
    const std::size_t exponent = token.find_first_of("eE");
    const bool underflow = exponent != std::string_view::npos
                               ? token.find('-', exponent) != std::string_view::npos
                               : token.find_first_not_of("-0.") != std::string_view::npos &&
                                     token.find('.') != std::string_view::npos &&
                                     token.find_first_not_of("-0") == token.find('.');
    return underflow ? 0.0 : std::numeric_limits<double>::infinity();
  }
  if (ec != std::errc()) {
    return std::nullopt;
  }
  return value;
}

std::int64_t int_at(const LineReader& reader, std::size_t k, const Item& item) {
  const std::optional<std::int64_t> value = parse_int(reader[k]);
  if (!value) {
    fail(item.source, item.line, item.element, item.prefix + "'" + std::string(reader[k]) + "' is not an integer");
  }
  return *value;
}

double double_at(const LineReader& reader, std::size_t k, const Item& item) {
  const std::optional<double> value = parse_double(reader[k]);
  if (!value) {
    fail(item.source, item.line, item.element, item.prefix + "'" + std::string(reader[k]) + "' is not a number");
  }
  return *value;
}

void expect_token_count(const LineReader& reader, std::size_t expected, const Item& item, const char* layout) {
  if (reader.size() != expected) {
    fail(item.source, item.line, item.element,
         item.prefix + "expected " + std::to_string(expected) + " values (" + layout + "), found " +
             std::to_string(reader.size()));
  }
}

Eigen::Vector3d position_at(const LineReader& reader, std::size_t k, const Item& item) {
  Eigen::Vector3d p(double_at(reader, k, item), double_at(reader, k + 1, item), double_at(reader, k + 2, item));
  if (!p.allFinite()) {
    fail(item.source, item.line, item.element, item.prefix + "coordinate is not finite");
  }
  return p;
}

std::size_t plausible_reserve(std::int64_t count, std::size_t text_size) {
  return static_cast<std::size_t>(std::clamp<std::int64_t>(count, 0, static_cast<std::int64_t>(text_size / 2)));
}

int region_index(std::vector<MeshRegion>& regions, const std::string& name) {
  for (std::size_t r = 0; r < regions.size(); ++r) {
    if (regions[r].name == name) return static_cast<int>(r);
  }
  regions.push_back({name, std::nullopt});
  return static_cast<int>(regions.size()) - 1;
}

std::string element_label(std::int64_t number) { return "element " + std::to_string(number) + ": "; }

}  // namespace mesh_io_detail

using namespace mesh_io_detail;  // NOLINT(google-build-using-namespace): the readers' own helpers

namespace {

/// Beyond this many individual "inverted" warnings, the rest are summarised in one line
/// (a whole file in the opposite convention would otherwise produce one message per tet).
constexpr int MAX_INVERTED_MESSAGES = 100;

/// Relative threshold of the zero-volume check: |V| <= ZERO_VOLUME_REL * diag^3 (mesh_io.hpp).
constexpr double ZERO_VOLUME_REL = 1e-12;

/// Where validate_tets' vertices and tets were read and how the file numbers them, for messages:
/// the file's own element numbers (Gmsh tags need not be index + base) and separate sources for
/// vertices and elements (TetGen keeps them in two files).
struct Sources {
  const std::string& vertex_source;
  const std::string& element_source;
  const std::vector<int>& vertex_lines;
  const std::vector<int>& element_lines;
  const std::vector<std::int64_t>* element_numbers;  ///< null: index + index_base
  int index_base;

  [[nodiscard]] int vertex_line(int v) const { return v < static_cast<int>(vertex_lines.size()) ? vertex_lines[v] : 0; }
  [[nodiscard]] int element_line(int t) const {
    return t < static_cast<int>(element_lines.size()) ? element_lines[t] : 0;
  }
  [[nodiscard]] std::int64_t element_number(int t) const {
    return element_numbers != nullptr ? (*element_numbers)[static_cast<std::size_t>(t)] : t + index_base;
  }
};

/// Refuses a mesh without vertices or tets, and region indices that do not match the regions.
void check_counts_and_regions(const TetMesh& mesh, const Sources& in) {
  const int tet_count = mesh.tet_count();
  if (mesh.vertex_count() == 0) {
    fail(in.vertex_source, 0, -1, "the mesh has no vertices");
  }
  if (tet_count == 0) {
    fail(in.element_source, 0, -1, "the mesh has no tetrahedra");
  }
  if (mesh.regions.empty() != mesh.tet_regions.empty() ||
      (!mesh.regions.empty() && mesh.tet_regions.size() != mesh.tets.size())) {
    fail(in.element_source, 0, -1,
         "regions: " + std::to_string(mesh.regions.size()) + " regions and " + std::to_string(mesh.tet_regions.size()) +
             " tet region indices for " + std::to_string(tet_count) + " tets (one per tet, or none at all)");
  }
  for (int t = 0; t < static_cast<int>(mesh.tet_regions.size()); ++t) {
    const int region = mesh.tet_regions[static_cast<std::size_t>(t)];
    if (region < 0 || region >= static_cast<int>(mesh.regions.size())) {
      fail(in.element_source, in.element_line(t), t,
           element_label(in.element_number(t)) + "region index " + std::to_string(region) + " outside [0, " +
               std::to_string(mesh.regions.size()) + ")");
    }
  }
}

/// Refuses a coordinate that is not finite; returns the zero-volume threshold ZERO_VOLUME_REL
/// (bounding-box diagonal)^3 [m^3].
double zero_volume_threshold_m3(const TetMesh& mesh, const Sources& in) {
  Eigen::Vector3d lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d upper = -lower;
  for (int v = 0; v < mesh.vertex_count(); ++v) {
    const Eigen::Vector3d& p = mesh.rest_positions_m[static_cast<std::size_t>(v)];
    if (!p.allFinite()) {
      fail(in.vertex_source, in.vertex_line(v), -1,
           "vertex " + std::to_string(v + in.index_base) + ": coordinate is not finite");
    }
    if (p.cwiseAbs().maxCoeff() > MAX_ABS_COORDINATE) {
      fail(in.vertex_source, in.vertex_line(v), -1,
           "vertex " + std::to_string(v + in.index_base) + ": coordinate beyond +-1e6 (MAX_ABS_COORDINATE)");
    }
    lower = lower.cwiseMin(p);
    upper = upper.cwiseMax(p);
  }
  const double diagonal_m = (upper - lower).norm();
  return ZERO_VOLUME_REL * diagonal_m * diagonal_m * diagonal_m;
}

/// Refuses a tet with a vertex index out of range, a repeated vertex or zero volume; re-orients an
/// inverted one (with a warning). Returns which vertices the tets use.
std::vector<char> orient_tets(TetMesh& mesh, const Sources& in, double zero_volume_m3, MeshWarnings* warnings) {
  const int vertex_count = mesh.vertex_count();
  const int index_base = in.index_base;
  std::vector<char> used(static_cast<std::size_t>(vertex_count), 0);
  int inverted = 0;
  for (int t = 0; t < mesh.tet_count(); ++t) {
    Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    const std::string label = element_label(in.element_number(t));
    for (int k = 0; k < 4; ++k) {
      if (tet[k] < 0 || tet[k] >= vertex_count) {
        fail(in.element_source, in.element_line(t), t,
             label + "vertex index " + std::to_string(static_cast<std::int64_t>(tet[k]) + index_base) +
                 " out of range [" + std::to_string(index_base) + ", " +
                 std::to_string(static_cast<std::int64_t>(vertex_count) - 1 + index_base) + "]");
      }
      for (int j = 0; j < k; ++j) {
        if (tet[j] == tet[k]) {
          fail(in.element_source, in.element_line(t), t,
               label + "zero-volume tet (vertex " + std::to_string(tet[k] + index_base) + " repeated)");
        }
      }
    }
    const double volume_m3 = signed_tet_volume(mesh.rest_positions_m[static_cast<std::size_t>(tet[0])],
                                               mesh.rest_positions_m[static_cast<std::size_t>(tet[1])],
                                               mesh.rest_positions_m[static_cast<std::size_t>(tet[2])],
                                               mesh.rest_positions_m[static_cast<std::size_t>(tet[3])]);
    if (std::abs(volume_m3) <= zero_volume_m3) {
      std::ostringstream what;
      what << label << "zero-volume tet (volume " << volume_m3 << " m^3, threshold " << zero_volume_m3 << " m^3)";
      fail(in.element_source, in.element_line(t), t, what.str());
    }
    if (volume_m3 < 0.0) {
      std::swap(tet[2], tet[3]);
      ++inverted;
      if (warnings != nullptr && inverted <= MAX_INVERTED_MESSAGES) {
        warnings->messages.push_back(location(in.element_source, in.element_line(t)) + ": " + label +
                                     "inverted tet (negative volume), re-oriented by swapping its vertices 3 and 4");
      }
    }
    for (const int v : tet) {
      used[static_cast<std::size_t>(v)] = 1;
    }
  }
  if (warnings != nullptr && inverted > MAX_INVERTED_MESSAGES) {
    warnings->messages.push_back(in.element_source + ": " + std::to_string(inverted - MAX_INVERTED_MESSAGES) +
                                 " more inverted tets re-oriented (" + std::to_string(inverted) + " in all)");
  }
  return used;
}

/// Refuses the first tet (in file order) with the vertex set of an earlier one.
void refuse_duplicates(const TetMesh& mesh, const Sources& in) {
  const int tet_count = mesh.tet_count();
  // Sort the sorted vertex sets; equal neighbours in that order are the same tet.
  std::vector<std::pair<Tet, int>> keys(static_cast<std::size_t>(tet_count));
  for (int t = 0; t < tet_count; ++t) {
    Tet key = mesh.tets[static_cast<std::size_t>(t)];
    std::sort(key.begin(), key.end());
    keys[static_cast<std::size_t>(t)] = {key, t};
  }
  std::sort(keys.begin(), keys.end());
  int first_duplicate = -1;
  int original = -1;
  for (std::size_t k = 1; k < keys.size(); ++k) {
    if (keys[k].first == keys[k - 1].first) {
      // keys[k-1] may itself be a later copy; the run's first entry is the earliest element.
      std::size_t run_begin = k - 1;
      while (run_begin > 0 && keys[run_begin - 1].first == keys[k].first) {
        --run_begin;
      }
      if (first_duplicate < 0 || keys[k].second < first_duplicate) {
        first_duplicate = keys[k].second;
        original = keys[run_begin].second;
      }
    }
  }
  if (first_duplicate >= 0) {
    std::string what = element_label(in.element_number(first_duplicate)) + "duplicate of element " +
                       std::to_string(in.element_number(original));
    if (in.element_line(original) > 0) {
      what += " (line " + std::to_string(in.element_line(original)) + ")";
    }
    fail(in.element_source, in.element_line(first_duplicate), first_duplicate, what);
  }
}

/// One warning for the vertices no tet uses (they would get no mass).
void warn_unused_vertices(const std::vector<char>& used, const Sources& in, MeshWarnings& warnings) {
  const auto unused = std::count(used.begin(), used.end(), 0);
  if (unused > 0) {
    const auto first = std::find(used.begin(), used.end(), 0) - used.begin();
    warnings.messages.push_back(location(in.vertex_source, in.vertex_line(static_cast<int>(first))) + ": " +
                                std::to_string(unused) + " vertices are not used by any tet (first: vertex " +
                                std::to_string(first + in.index_base) + ")");
  }
}

/// Refuses a face shared by more than two tets (overlapping elements: the core's adjacency has no
/// place for them), naming the file and the third tet.
void refuse_overlaps(const TetMesh& mesh, const Sources& in) {
  try {
    check_face_sharing(mesh);
  } catch (const MeshError& error) {
    const int t = error.element();
    fail(in.element_source, t >= 0 ? in.element_line(t) : 0, t, error.what());
  }
}

/// validate_tets, with the Sources of the vertices and tets.
void validate_impl(TetMesh& mesh, const Sources& in, MeshWarnings* warnings) {
  check_counts_and_regions(mesh, in);
  const double zero_volume_m3 = zero_volume_threshold_m3(mesh, in);
  const std::vector<char> used = orient_tets(mesh, in, zero_volume_m3, warnings);
  refuse_duplicates(mesh, in);
  refuse_overlaps(mesh, in);
  if (warnings != nullptr) {
    warn_unused_vertices(used, in, *warnings);
  }
}

}  // namespace

TetMesh mesh_io_detail::finish(RawMesh raw, const std::string& vertex_source, const std::string& element_source,
                               MeshWarnings* warnings) {
  TetMesh mesh;
  mesh.rest_positions_m = std::move(raw.positions);
  const std::int64_t vertex_count = mesh.vertex_count();
  mesh.tets.resize(raw.tets.size());
  for (std::size_t t = 0; t < raw.tets.size(); ++t) {
    for (int k = 0; k < 4; ++k) {
      const std::int64_t number = raw.tets[t][static_cast<std::size_t>(k)];
      if (number < raw.vertex_base || number >= raw.vertex_base + vertex_count) {
        fail(element_source, raw.element_lines[t], static_cast<int>(t),
             element_label(raw.element_numbers[t]) + "vertex index " + std::to_string(number) + " out of range [" +
                 std::to_string(raw.vertex_base) + ", " + std::to_string(raw.vertex_base + vertex_count - 1) + "]");
      }
      mesh.tets[t][static_cast<std::size_t>(k)] = static_cast<int>(number - raw.vertex_base);
    }
  }
  if (!raw.regions.empty()) {
    for (std::size_t t = 0; t < raw.tets.size(); ++t) {
      if (raw.tet_regions[t] < 0) {
        fail(element_source, raw.element_lines[t], static_cast<int>(t),
             element_label(raw.element_numbers[t]) + "is in no region, while the file gives others regions (" +
                 quoted_region_names(raw.regions) + ")");
      }
    }
    mesh.regions = std::move(raw.regions);
    mesh.tet_regions = std::move(raw.tet_regions);
  }
  validate_impl(mesh,
                Sources{vertex_source, element_source, raw.vertex_lines, raw.element_lines, &raw.element_numbers,
                        static_cast<int>(raw.vertex_base)},
                warnings);
  return mesh;
}

// ---------------------------------------------------------------------------------------------

void validate_tets(TetMesh& mesh, const std::string& source_name, const std::vector<int>& vertex_lines,
                   const std::vector<int>& element_lines, int index_base, MeshWarnings* warnings) {
  validate_impl(mesh, Sources{source_name, source_name, vertex_lines, element_lines, nullptr, index_base}, warnings);
}

TetMesh read_mesh(const std::filesystem::path& path, MeshWarnings* warnings) {
  const std::string extension = to_upper(path.extension().string());
  if (extension == ".VEG") {
    return read_veg(path, warnings);
  }
  if (extension == ".NODE" || extension == ".ELE") {
    return read_tetgen(path, warnings);
  }
  if (extension == ".MSH") {
    return read_gmsh(path, warnings);
  }
  fail(path.string(), 0, -1,
       "unknown mesh format '" + path.extension().string() + "' (expected .veg, .node/.ele or .msh)");
}

}  // namespace tissue
