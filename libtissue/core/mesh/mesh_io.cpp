// Mesh readers (Vega .veg, TetGen .node/.ele, Gmsh .msh 4.1 ASCII, Vega .bou) and the checks
// every reader applies. Each reader first collects what the file says into a RawMesh (vertex
// numbers as written in the file), then one common path maps the numbers to 0-based indices and
// validates, so every format refuses bad input with the same messages.
#include "core/mesh/mesh_io.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>
#include <system_error>
#include <unordered_map>

namespace tissue {
namespace {

/// Beyond this many individual "inverted" warnings, the rest are summarised in one line
/// (a whole file in the opposite convention would otherwise produce one message per tet).
constexpr int MAX_INVERTED_MESSAGES = 100;

/// Relative threshold of the zero-volume check: |V| <= ZERO_VOLUME_REL * diag^3 (mesh_io.hpp).
constexpr double ZERO_VOLUME_REL = 1e-12;

std::string location(const std::string& source, int line) {
  if (line > 0) {
    return source + ":" + std::to_string(line);
  }
  return source;
}

/// Throws the MeshError every reader uses: "<source>:<line>: <what>" (line omitted when 0).
[[noreturn]] void fail(const std::string& source, int line, int element, const std::string& what) {
  throw MeshError(location(source, line) + ": " + what, source, line, element);
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    fail(path.string(), 0, -1, "cannot open file");
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) {
    fail(path.string(), 0, -1, "read error");
  }
  return std::move(buffer).str();
}

std::string to_upper(std::string_view text) {
  std::string result(text);
  for (char& c : result) {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return result;
}

/// Walks a text line by line, skipping lines that hold no token after comment removal, and
/// splits each remaining line into whitespace (optionally also comma) separated tokens.
class LineReader {
 public:
  LineReader(std::string_view text, char comment, bool commas_separate)
      : m_text(text), m_comment(comment), m_commas_separate(commas_separate) {}

  /// Advances to the next line with at least one token. At the end of the text returns false
  /// and line() is the number of the last line, which is where truncation is reported.
  bool next() {
    if (m_unread) {
      m_unread = false;
      return true;
    }
    while (m_pos < m_text.size()) {
      std::size_t end = m_text.find('\n', m_pos);
      if (end == std::string_view::npos) {
        end = m_text.size();
      }
      std::string_view line = m_text.substr(m_pos, end - m_pos);
      m_pos = end + 1;
      ++m_line;
      if (m_comment != '\0') {
        const std::size_t comment = line.find(m_comment);
        if (comment != std::string_view::npos) {
          line = line.substr(0, comment);
        }
      }
      tokenize(line);
      if (!m_tokens.empty()) {
        return true;
      }
    }
    return false;
  }

  /// Makes the next call of next() return the current line again.
  void unread() { m_unread = true; }

  [[nodiscard]] int line() const { return m_line; }
  [[nodiscard]] const std::vector<std::string_view>& tokens() const { return m_tokens; }
  [[nodiscard]] std::size_t size() const { return m_tokens.size(); }
  [[nodiscard]] std::string_view operator[](std::size_t k) const { return m_tokens[k]; }

 private:
  [[nodiscard]] bool is_separator(char c) const {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || (m_commas_separate && c == ',');
  }

  void tokenize(std::string_view line) {
    m_tokens.clear();
    std::size_t k = 0;
    while (k < line.size()) {
      while (k < line.size() && is_separator(line[k])) {
        ++k;
      }
      const std::size_t begin = k;
      while (k < line.size() && !is_separator(line[k])) {
        ++k;
      }
      if (k > begin) {
        m_tokens.push_back(line.substr(begin, k - begin));
      }
    }
  }

  std::string_view m_text;
  char m_comment;
  bool m_commas_separate;
  std::size_t m_pos = 0;
  int m_line = 0;
  bool m_unread = false;
  std::vector<std::string_view> m_tokens;
};

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

/// Context for messages about one item of a file: where it is and how the file numbers it.
struct Item {
  const std::string& source;
  int line;
  int element;         ///< 0-based tet index for MeshError, -1 if not an element
  std::string prefix;  ///< e.g. "element 12: " or "vertex 3: " or "*VERTICES header: "
};

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

/// Reads three coordinates starting at token k and refuses NaN/Inf.
Eigen::Vector3d position_at(const LineReader& reader, std::size_t k, const Item& item) {
  Eigen::Vector3d p(double_at(reader, k, item), double_at(reader, k + 1, item), double_at(reader, k + 2, item));
  if (!p.allFinite()) {
    fail(item.source, item.line, item.element, item.prefix + "coordinate is not finite");
  }
  return p;
}

/// Element counts in headers are used to reserve memory; a corrupt header must not make us
/// allocate gigabytes before the truncation is noticed, so a count is only trusted up to what
/// the text could possibly hold (one item per two characters).
std::size_t plausible_reserve(std::int64_t count, std::size_t text_size) {
  return static_cast<std::size_t>(std::clamp<std::int64_t>(count, 0, static_cast<std::int64_t>(text_size / 2)));
}

/// What a file says, before vertex numbers are mapped to indices and tets are checked.
struct RawMesh {
  std::vector<Eigen::Vector3d> positions;
  std::vector<int> vertex_lines;
  std::vector<std::array<std::int64_t, 4>> tets;  ///< vertex numbers as written in the file
  std::vector<int> element_lines;
  std::vector<std::int64_t> element_numbers;  ///< the file's own element numbers, for messages
  std::int64_t vertex_base = 0;               ///< the file's number of vertex 0
  std::vector<MeshRegion> regions;            ///< as the file declares them (issue 25)
  std::vector<int> tet_regions;               ///< per tet, an index into regions, -1 none; empty: no regions
};

/// The index of the region of that name, appended (without a material) if new.
int region_index(std::vector<MeshRegion>& regions, const std::string& name) {
  for (std::size_t r = 0; r < regions.size(); ++r) {
    if (regions[r].name == name) return static_cast<int>(r);
  }
  regions.push_back({name, std::nullopt});
  return static_cast<int>(regions.size()) - 1;
}

std::string element_label(std::int64_t number) { return "element " + std::to_string(number) + ": "; }

/// validate_tets, with the file's own element numbers (Gmsh tags need not be index + base) and
/// separate sources for vertices and elements (TetGen keeps them in two files).
void validate_impl(TetMesh& mesh, const std::string& vertex_source, const std::string& element_source,
                   const std::vector<int>& vertex_lines, const std::vector<int>& element_lines,
                   const std::vector<std::int64_t>* element_numbers, int index_base, MeshWarnings* warnings) {
  const auto vertex_line = [&](int v) { return v < static_cast<int>(vertex_lines.size()) ? vertex_lines[v] : 0; };
  const auto element_line = [&](int t) { return t < static_cast<int>(element_lines.size()) ? element_lines[t] : 0; };
  const auto element_number = [&](int t) -> std::int64_t {
    return element_numbers != nullptr ? (*element_numbers)[static_cast<std::size_t>(t)] : t + index_base;
  };

  const int vertex_count = mesh.vertex_count();
  const int tet_count = mesh.tet_count();
  if (vertex_count == 0) {
    fail(vertex_source, 0, -1, "the mesh has no vertices");
  }
  if (tet_count == 0) {
    fail(element_source, 0, -1, "the mesh has no tetrahedra");
  }
  if (mesh.regions.empty() != mesh.tet_regions.empty() ||
      (!mesh.regions.empty() && mesh.tet_regions.size() != mesh.tets.size())) {
    fail(element_source, 0, -1,
         "regions: " + std::to_string(mesh.regions.size()) + " regions and " + std::to_string(mesh.tet_regions.size()) +
             " tet region indices for " + std::to_string(tet_count) + " tets (one per tet, or none at all)");
  }
  for (int t = 0; t < static_cast<int>(mesh.tet_regions.size()); ++t) {
    const int region = mesh.tet_regions[static_cast<std::size_t>(t)];
    if (region < 0 || region >= static_cast<int>(mesh.regions.size())) {
      fail(element_source, element_line(t), t,
           element_label(element_number(t)) + "region index " + std::to_string(region) + " outside [0, " +
               std::to_string(mesh.regions.size()) + ")");
    }
  }

  Eigen::Vector3d lower = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d upper = -lower;
  for (int v = 0; v < vertex_count; ++v) {
    const Eigen::Vector3d& p = mesh.rest_positions_m[static_cast<std::size_t>(v)];
    if (!p.allFinite()) {
      fail(vertex_source, vertex_line(v), -1,
           "vertex " + std::to_string(v + index_base) + ": coordinate is not finite");
    }
    lower = lower.cwiseMin(p);
    upper = upper.cwiseMax(p);
  }
  const double diagonal_m = (upper - lower).norm();
  const double zero_volume_m3 = ZERO_VOLUME_REL * diagonal_m * diagonal_m * diagonal_m;

  std::vector<char> used(static_cast<std::size_t>(vertex_count), 0);
  int inverted = 0;
  for (int t = 0; t < tet_count; ++t) {
    Tet& tet = mesh.tets[static_cast<std::size_t>(t)];
    const std::string label = element_label(element_number(t));
    for (int k = 0; k < 4; ++k) {
      if (tet[k] < 0 || tet[k] >= vertex_count) {
        fail(element_source, element_line(t), t,
             label + "vertex index " + std::to_string(static_cast<std::int64_t>(tet[k]) + index_base) +
                 " out of range [" + std::to_string(index_base) + ", " +
                 std::to_string(static_cast<std::int64_t>(vertex_count) - 1 + index_base) + "]");
      }
      for (int j = 0; j < k; ++j) {
        if (tet[j] == tet[k]) {
          fail(element_source, element_line(t), t,
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
      fail(element_source, element_line(t), t, what.str());
    }
    if (volume_m3 < 0.0) {
      std::swap(tet[2], tet[3]);
      ++inverted;
      if (warnings != nullptr && inverted <= MAX_INVERTED_MESSAGES) {
        warnings->messages.push_back(location(element_source, element_line(t)) + ": " + label +
                                     "inverted tet (negative volume), re-oriented by swapping its vertices 3 and 4");
      }
    }
    for (const int v : tet) {
      used[static_cast<std::size_t>(v)] = 1;
    }
  }
  if (warnings != nullptr && inverted > MAX_INVERTED_MESSAGES) {
    warnings->messages.push_back(element_source + ": " + std::to_string(inverted - MAX_INVERTED_MESSAGES) +
                                 " more inverted tets re-oriented (" + std::to_string(inverted) + " in all)");
  }

  // Duplicates: sort the sorted vertex sets; equal neighbours in that order are the same tet.
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
    std::string what = element_label(element_number(first_duplicate)) + "duplicate of element " +
                       std::to_string(element_number(original));
    if (element_line(original) > 0) {
      what += " (line " + std::to_string(element_line(original)) + ")";
    }
    fail(element_source, element_line(first_duplicate), first_duplicate, what);
  }

  if (warnings != nullptr) {
    const auto unused = std::count(used.begin(), used.end(), 0);
    if (unused > 0) {
      const auto first = std::find(used.begin(), used.end(), 0) - used.begin();
      warnings->messages.push_back(location(vertex_source, vertex_line(static_cast<int>(first))) + ": " +
                                   std::to_string(unused) + " vertices are not used by any tet (first: vertex " +
                                   std::to_string(first + index_base) + ")");
    }
  }
}

/// Maps the file's vertex numbers to 0-based indices (refusing those out of range) and validates.
TetMesh finish(RawMesh raw, const std::string& vertex_source, const std::string& element_source,
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
  validate_impl(mesh, vertex_source, element_source, raw.vertex_lines, raw.element_lines, &raw.element_numbers,
                static_cast<int>(raw.vertex_base), warnings);
  return mesh;
}

// ---------------------------------------------------------------------------------------------
// Vega .veg

bool is_veg_keyword(const LineReader& reader) { return reader[0].front() == '*'; }

/// Next data line of the current section; false (with the keyword line put back) at a new
/// section or at the end of the text.
bool next_veg_data(LineReader& reader) {
  if (!reader.next()) {
    return false;
  }
  if (is_veg_keyword(reader)) {
    reader.unread();
    return false;
  }
  return true;
}

/// Reads the header "count n ..." of a section; returns count after checking n.
std::int64_t read_veg_header(LineReader& reader, const std::string& source, const char* section,
                             std::int64_t expected_second, const char* layout) {
  if (!next_veg_data(reader)) {
    fail(source, reader.line(), -1, std::string(section) + ": missing the header line '" + layout + "'");
  }
  const Item header{source, reader.line(), -1, std::string(section) + " header: "};
  if (reader.size() < 2) {
    fail(source, reader.line(), -1, header.prefix + "expected '" + layout + "'");
  }
  const std::int64_t count = int_at(reader, 0, header);
  const std::int64_t second = int_at(reader, 1, header);
  if (count < 0) {
    fail(source, reader.line(), -1, header.prefix + "negative count " + std::to_string(count));
  }
  if (second != expected_second) {
    fail(source, reader.line(), -1,
         header.prefix + "expected " + std::to_string(expected_second) + " as second value ('" + layout + "'), found " +
             std::to_string(second));
  }
  for (std::size_t k = 2; k < reader.size(); ++k) {
    int_at(reader, k, header);
  }
  return count;
}

void refuse_extra_veg_lines(LineReader& reader, const std::string& source, const char* section, std::int64_t count) {
  if (next_veg_data(reader)) {
    fail(source, reader.line(), -1,
         std::string(section) + ": more lines than the count " + std::to_string(count) + " in its header");
  }
}

void read_veg_vertices(LineReader& reader, const std::string& source, RawMesh& raw, std::size_t text_size) {
  const std::int64_t count = read_veg_header(reader, source, "*VERTICES", 3, "count 3 0 0");
  raw.positions.reserve(plausible_reserve(count, text_size));
  raw.vertex_lines.reserve(plausible_reserve(count, text_size));
  for (std::int64_t k = 0; k < count; ++k) {
    if (!next_veg_data(reader)) {
      fail(source, reader.line(), -1,
           "*VERTICES: truncated, expected " + std::to_string(count) + " vertices, found " + std::to_string(k));
    }
    const Item item{source, reader.line(), -1, "vertex " + std::to_string(k + 1) + ": "};
    expect_token_count(reader, 4, item, "id x y z");
    const std::int64_t id = int_at(reader, 0, item);
    if (id != k + 1) {
      fail(source, reader.line(), -1,
           item.prefix + "id " + std::to_string(id) + " out of sequence (vertices are numbered 1, 2, ...)");
    }
    raw.positions.push_back(position_at(reader, 1, item));
    raw.vertex_lines.push_back(reader.line());
  }
  refuse_extra_veg_lines(reader, source, "*VERTICES", count);
}

void read_veg_elements(LineReader& reader, const std::string& source, RawMesh& raw, std::size_t text_size) {
  if (!next_veg_data(reader)) {
    fail(source, reader.line(), -1, "*ELEMENTS: missing the element type line 'TET'");
  }
  if (to_upper(reader[0]) != "TET" || reader.size() != 1) {
    fail(source, reader.line(), -1,
         "*ELEMENTS: element type '" + std::string(reader[0]) + "' is not supported (only TET)");
  }
  const std::int64_t count = read_veg_header(reader, source, "*ELEMENTS", 4, "count 4 0");
  raw.tets.reserve(plausible_reserve(count, text_size));
  raw.element_lines.reserve(plausible_reserve(count, text_size));
  raw.element_numbers.reserve(plausible_reserve(count, text_size));
  for (std::int64_t k = 0; k < count; ++k) {
    if (!next_veg_data(reader)) {
      fail(source, reader.line(), -1,
           "*ELEMENTS: truncated, expected " + std::to_string(count) + " elements, found " + std::to_string(k));
    }
    const Item item{source, reader.line(), static_cast<int>(k), element_label(k + 1)};
    expect_token_count(reader, 5, item, "id v1 v2 v3 v4");
    const std::int64_t id = int_at(reader, 0, item);
    if (id != k + 1) {
      fail(source, reader.line(), static_cast<int>(k),
           item.prefix + "id " + std::to_string(id) + " out of sequence (elements are numbered 1, 2, ...)");
    }
    raw.tets.push_back(
        {int_at(reader, 1, item), int_at(reader, 2, item), int_at(reader, 3, item), int_at(reader, 4, item)});
    raw.element_lines.push_back(reader.line());
    raw.element_numbers.push_back(k + 1);
  }
  refuse_extra_veg_lines(reader, source, "*ELEMENTS", count);
}

/// What a .veg file says of materials and regions (Vega's grammar): `*MATERIAL name` then
/// `ENU, density, E, nu`; `*SET name` then 1-based element numbers, comma separated, on any number
/// of lines (`allElements` is predefined); `*REGION` then `set, material` lines.
struct VegRegions {
  struct NamedMaterial {
    std::string name;
    Material material;
    int line = 0;
  };
  struct Set {
    std::vector<std::int64_t> elements;
    int line = 0;
  };
  struct Assignment {
    std::string set, material;
    int line = 0;
  };
  std::vector<NamedMaterial> materials;
  std::map<std::string, Set> sets;
  std::vector<Assignment> assignments;
};

std::string veg_section_name(const LineReader& reader, const std::string& source, const char* section) {
  if (reader.size() != 2) {
    fail(source, reader.line(), -1, std::string(section) + ": expected '" + section + " name'");
  }
  return std::string(reader[1]);
}

void read_veg_material(LineReader& reader, const std::string& source, VegRegions& regions) {
  VegRegions::NamedMaterial named{veg_section_name(reader, source, "*MATERIAL"), {}, reader.line()};
  for (const auto& other : regions.materials) {
    if (other.name == named.name) {
      fail(source, reader.line(), -1,
           "*MATERIAL " + named.name + ": defined twice (first at line " + std::to_string(other.line) + ")");
    }
  }
  const std::string prefix = "*MATERIAL " + named.name + ": ";
  if (!next_veg_data(reader)) fail(source, reader.line(), -1, prefix + "missing the line 'ENU, density, E, nu'");
  if (to_upper(reader[0]) != "ENU") {
    fail(source, reader.line(), -1,
         prefix + "material type '" + std::string(reader[0]) + "' is not supported (only ENU: density, E, nu)");
  }
  const Item item{source, reader.line(), -1, prefix};
  expect_token_count(reader, 4, item, "ENU, density, E, nu");
  named.material = {double_at(reader, 2, item), double_at(reader, 3, item), double_at(reader, 1, item)};
  try {
    validate(named.material);
  } catch (const ParameterError& error) {
    fail(source, reader.line(), -1, prefix + error.what());
  }
  if (next_veg_data(reader)) fail(source, reader.line(), -1, prefix + "one line 'ENU, density, E, nu' expected");
  regions.materials.push_back(std::move(named));
}

void read_veg_set(LineReader& reader, const std::string& source, VegRegions& regions) {
  const std::string name = veg_section_name(reader, source, "*SET");
  VegRegions::Set set;
  set.line = reader.line();
  if (name == "allElements" || regions.sets.count(name) != 0) {
    fail(source, reader.line(), -1, "*SET " + name + ": defined twice (allElements is predefined)");
  }
  while (next_veg_data(reader)) {
    const Item item{source, reader.line(), -1, "*SET " + name + ": "};
    for (std::size_t k = 0; k < reader.size(); ++k) set.elements.push_back(int_at(reader, k, item));
  }
  if (set.elements.empty() && reader.next()) {
    if (to_upper(reader[0]) == "*INCLUDE") {
      fail(source, reader.line(), -1,
           "*SET " + name + ": its elements are in an *INCLUDE'd file, which is not read (write them in the .veg)");
    }
    reader.unread();
  }
  regions.sets.emplace(name, std::move(set));
}

void read_veg_region(LineReader& reader, const std::string& source, VegRegions& regions) {
  if (reader.size() != 1) fail(source, reader.line(), -1, "*REGION: expected '*REGION' alone on its line");
  bool any = false;
  while (next_veg_data(reader)) {
    if (reader.size() != 2) fail(source, reader.line(), -1, "*REGION: expected 'set, material'");
    regions.assignments.push_back({std::string(reader[0]), std::string(reader[1]), reader.line()});
    any = true;
  }
  if (!any) fail(source, reader.line(), -1, "*REGION: missing the line 'set, material'");
}

/// Gives each *REGION's set its material: the regions, named by their sets, and each tet's region.
void resolve_veg_regions(const VegRegions& regions, const std::string& source, RawMesh& raw, MeshWarnings* warnings) {
  const auto tet_count = static_cast<std::int64_t>(raw.tets.size());
  if (regions.assignments.empty()) {
    for (const auto& material : regions.materials) {
      if (warnings != nullptr) {
        warnings->messages.push_back(location(source, material.line) + ": *MATERIAL " + material.name +
                                     " is given to no *REGION: not used");
      }
    }
    return;
  }
  raw.tet_regions.assign(raw.tets.size(), -1);
  for (const VegRegions::Assignment& assignment : regions.assignments) {
    const std::string prefix = "*REGION " + assignment.set + ", " + assignment.material + ": ";
    const VegRegions::Set* set = nullptr;
    VegRegions::Set everything;
    if (assignment.set == "allElements") {
      everything.elements.resize(static_cast<std::size_t>(tet_count));
      std::iota(everything.elements.begin(), everything.elements.end(), std::int64_t{1});
      everything.line = assignment.line;
      set = &everything;
    } else if (const auto found = regions.sets.find(assignment.set); found != regions.sets.end()) {
      set = &found->second;
    } else {
      fail(source, assignment.line, -1, prefix + "no *SET named " + assignment.set);
    }
    const VegRegions::NamedMaterial* material = nullptr;
    for (const auto& named : regions.materials) {
      if (named.name == assignment.material) material = &named;
    }
    if (material == nullptr) fail(source, assignment.line, -1, prefix + "no *MATERIAL named " + assignment.material);
    for (const MeshRegion& region : raw.regions) {
      if (region.name == assignment.set) fail(source, assignment.line, -1, prefix + "the set is given a region twice");
    }
    raw.regions.push_back({assignment.set, material->material});
    const int index = static_cast<int>(raw.regions.size()) - 1;
    for (const std::int64_t element : set->elements) {
      if (element < 1 || element > tet_count) {
        fail(source, set->line, -1,
             "*SET " + assignment.set + ": element " + std::to_string(element) + " outside [1, " +
                 std::to_string(tet_count) + "]");
      }
      int& region = raw.tet_regions[static_cast<std::size_t>(element - 1)];
      if (region >= 0 && region != index) {
        fail(source, assignment.line, static_cast<int>(element - 1),
             prefix + "element " + std::to_string(element) + " is in two regions, " + raw.regions[static_cast<std::size_t>(region)].name +
                 " and " + assignment.set);
      }
      region = index;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// TetGen .node / .ele

void read_tetgen_nodes(std::string_view text, const std::string& source, RawMesh& raw) {
  LineReader reader(text, '#', false);
  if (!reader.next()) {
    fail(source, reader.line(), -1, "empty file: missing the header '<#points> 3 <#attributes> <#markers>'");
  }
  const Item header{source, reader.line(), -1, "header: "};
  if (reader.size() < 2 || reader.size() > 4) {
    fail(source, reader.line(), -1, header.prefix + "expected '<#points> 3 <#attributes> <#markers>'");
  }
  const std::int64_t count = int_at(reader, 0, header);
  const std::int64_t dimension = int_at(reader, 1, header);
  const std::int64_t attributes = reader.size() > 2 ? int_at(reader, 2, header) : 0;
  const std::int64_t markers = reader.size() > 3 ? int_at(reader, 3, header) : 0;
  if (count < 0 || dimension != 3 || attributes < 0 || attributes > 1000 || markers < 0 || markers > 1) {
    fail(source, reader.line(), -1,
         header.prefix + "expected '<#points> 3 <#attributes> <0|1>' with non-negative counts");
  }
  const auto columns = static_cast<std::size_t>(4 + attributes + markers);
  raw.positions.reserve(plausible_reserve(count, text.size()));
  raw.vertex_lines.reserve(plausible_reserve(count, text.size()));
  for (std::int64_t k = 0; k < count; ++k) {
    if (!reader.next()) {
      fail(source, reader.line(), -1,
           "truncated, expected " + std::to_string(count) + " points, found " + std::to_string(k));
    }
    const Item first{source, reader.line(), -1, "point: "};
    const std::int64_t id = int_at(reader, 0, first);
    if (k == 0) {
      if (id != 0 && id != 1) {
        fail(source, reader.line(), -1, "point " + std::to_string(id) + ": the first point must be numbered 0 or 1");
      }
      raw.vertex_base = id;
    }
    const Item item{source, reader.line(), -1, "point " + std::to_string(id) + ": "};
    if (id != raw.vertex_base + k) {
      fail(source, reader.line(), -1, item.prefix + "out of sequence, expected " + std::to_string(raw.vertex_base + k));
    }
    expect_token_count(reader, columns, item, "index x y z [attributes] [marker]");
    raw.positions.push_back(position_at(reader, 1, item));
    for (std::size_t c = 4; c < columns; ++c) {
      double_at(reader, c, item);
    }
    raw.vertex_lines.push_back(reader.line());
  }
  if (reader.next()) {
    fail(source, reader.line(), -1, "more lines than the count " + std::to_string(count) + " in the header");
  }
}

void read_tetgen_elements(std::string_view text, const std::string& source, RawMesh& raw) {
  LineReader reader(text, '#', false);
  if (!reader.next()) {
    fail(source, reader.line(), -1, "empty file: missing the header '<#tetrahedra> <4|10> <#attributes>'");
  }
  const Item header{source, reader.line(), -1, "header: "};
  if (reader.size() < 2 || reader.size() > 3) {
    fail(source, reader.line(), -1, header.prefix + "expected '<#tetrahedra> <4|10> <#attributes>'");
  }
  const std::int64_t count = int_at(reader, 0, header);
  const std::int64_t nodes = int_at(reader, 1, header);
  const std::int64_t attributes = reader.size() > 2 ? int_at(reader, 2, header) : 0;
  if (count < 0 || (nodes != 4 && nodes != 10) || attributes < 0 || attributes > 1000) {
    fail(source, reader.line(), -1,
         header.prefix + "expected '<#tetrahedra> <4|10> <#attributes>' with non-negative counts");
  }
  const auto columns = static_cast<std::size_t>(1 + nodes + attributes);
  raw.tets.reserve(plausible_reserve(count, text.size()));
  raw.element_lines.reserve(plausible_reserve(count, text.size()));
  raw.element_numbers.reserve(plausible_reserve(count, text.size()));
  for (std::int64_t k = 0; k < count; ++k) {
    if (!reader.next()) {
      fail(source, reader.line(), -1,
           "truncated, expected " + std::to_string(count) + " tetrahedra, found " + std::to_string(k));
    }
    const Item first{source, reader.line(), static_cast<int>(k), "element: "};
    const std::int64_t id = int_at(reader, 0, first);
    const Item item{source, reader.line(), static_cast<int>(k), element_label(id)};
    expect_token_count(reader, columns, item, "index v1 v2 v3 v4 [...] [attributes]");
    // Quadratic (10-node) tets: the first four are the corners; the edge nodes are ignored.
    raw.tets.push_back(
        {int_at(reader, 1, item), int_at(reader, 2, item), int_at(reader, 3, item), int_at(reader, 4, item)});
    for (std::size_t c = 5; c < static_cast<std::size_t>(1 + nodes); ++c) {
      int_at(reader, c, item);
    }
    for (std::size_t c = static_cast<std::size_t>(1 + nodes); c < columns; ++c) {
      double_at(reader, c, item);
    }
    if (attributes > 0) {
      // The first attribute is the region (tetgen -A); its number, as written, names it.
      const std::size_t c = static_cast<std::size_t>(1 + nodes);
      const double attribute = double_at(reader, c, item);
      if (attribute != std::floor(attribute) || std::abs(attribute) > 1e9) {
        fail(source, reader.line(), static_cast<int>(k),
             item.prefix + "region attribute " + std::string(reader[c]) + " is not a whole number (tetgen -A)");
      }
      raw.tet_regions.push_back(region_index(raw.regions, std::to_string(static_cast<std::int64_t>(attribute))));
    }
    raw.element_lines.push_back(reader.line());
    raw.element_numbers.push_back(id);
  }
  if (reader.next()) {
    fail(source, reader.line(), -1, "more lines than the count " + std::to_string(count) + " in the header");
  }
}

// ---------------------------------------------------------------------------------------------
// Gmsh .msh 4.1 ASCII

bool is_gmsh_section_line(const LineReader& reader) { return reader[0].front() == '$'; }

/// Next data line inside a section; false (line put back) at a $-line or the end of the text.
bool next_gmsh_data(LineReader& reader) {
  if (!reader.next()) {
    return false;
  }
  if (is_gmsh_section_line(reader)) {
    reader.unread();
    return false;
  }
  return true;
}

void expect_gmsh_end(LineReader& reader, const std::string& source, const std::string& section) {
  const std::string end = "$End" + section.substr(1);
  if (!reader.next()) {
    fail(source, reader.line(), -1, section + ": missing " + end);
  }
  if (reader[0] != end) {
    fail(source, reader.line(), -1,
         section + ": expected " + end + ", found '" + std::string(reader[0]) + "' (counts in the section are wrong)");
  }
}

/// Reads a line of exactly `n` integers, as the $Nodes and $Elements headers are.
std::vector<std::int64_t> read_gmsh_ints(LineReader& reader, const std::string& source, const std::string& what,
                                         std::size_t n, const std::string& section) {
  if (!next_gmsh_data(reader)) {
    fail(source, reader.line(), -1, section + ": truncated, missing " + what);
  }
  const Item item{source, reader.line(), -1, section + " " + what + ": "};
  expect_token_count(reader, n, item, what.c_str());
  std::vector<std::int64_t> values(n);
  for (std::size_t k = 0; k < n; ++k) {
    values[k] = int_at(reader, k, item);
  }
  return values;
}

void read_gmsh_format(LineReader& reader, const std::string& source) {
  if (!next_gmsh_data(reader)) {
    fail(source, reader.line(), -1, "$MeshFormat: missing 'version file-type data-size'");
  }
  if (reader.size() != 3) {
    fail(source, reader.line(), -1, "$MeshFormat: expected 'version file-type data-size'");
  }
  if (reader[0] != "4.1") {
    fail(source, reader.line(), -1,
         "$MeshFormat: version " + std::string(reader[0]) + " is not supported (save as 4.1: gmsh -format msh41)");
  }
  if (reader[1] != "0") {
    fail(source, reader.line(), -1, "$MeshFormat: binary .msh is not supported (save as ASCII, without -bin)");
  }
  expect_gmsh_end(reader, source, "$MeshFormat");
}

void read_gmsh_nodes(LineReader& reader, const std::string& source, RawMesh& raw,
                     std::unordered_map<std::int64_t, int>& index_of_tag, std::size_t text_size) {
  const std::string section = "$Nodes";
  const auto header =
      read_gmsh_ints(reader, source, "header 'numEntityBlocks numNodes minNodeTag maxNodeTag'", 4, section);
  const std::int64_t blocks = header[0];
  const std::int64_t count = header[1];
  if (blocks < 0 || count < 0) {
    fail(source, reader.line(), -1, section + ": negative count in the header");
  }
  raw.positions.reserve(plausible_reserve(count, text_size));
  raw.vertex_lines.reserve(plausible_reserve(count, text_size));
  index_of_tag.reserve(plausible_reserve(count, text_size));
  std::vector<std::int64_t> tags;
  for (std::int64_t b = 0; b < blocks; ++b) {
    const auto block =
        read_gmsh_ints(reader, source, "entity block 'entityDim entityTag parametric numNodesInBlock'", 4, section);
    const std::int64_t entity_dim = block[0];
    const std::int64_t in_block = block[3];
    if (entity_dim < 0 || entity_dim > 3 || block[2] < 0 || block[2] > 1 || in_block < 0) {
      fail(source, reader.line(), -1, section + ": invalid entity block header");
    }
    const auto columns = static_cast<std::size_t>(3 + (block[2] == 1 ? entity_dim : 0));
    tags.clear();
    for (std::int64_t k = 0; k < in_block; ++k) {
      if (!next_gmsh_data(reader)) {
        fail(source, reader.line(), -1, section + ": truncated, node tags of an entity block missing");
      }
      const Item item{source, reader.line(), -1, "node tag: "};
      expect_token_count(reader, 1, item, "nodeTag");
      const std::int64_t tag = int_at(reader, 0, item);
      if (tag <= 0) {
        fail(source, reader.line(), -1, "node " + std::to_string(tag) + ": tags must be positive");
      }
      if (!index_of_tag.emplace(tag, static_cast<int>(raw.positions.size() + tags.size())).second) {
        fail(source, reader.line(), -1, "node " + std::to_string(tag) + ": tag defined twice");
      }
      tags.push_back(tag);
    }
    for (const std::int64_t tag : tags) {
      if (!next_gmsh_data(reader)) {
        fail(source, reader.line(), -1, section + ": truncated, coordinates of an entity block missing");
      }
      const Item item{source, reader.line(), -1, "node " + std::to_string(tag) + ": "};
      expect_token_count(reader, columns, item, columns == 3 ? "x y z" : "x y z u [v [w]]");
      raw.positions.push_back(position_at(reader, 0, item));
      raw.vertex_lines.push_back(reader.line());
    }
  }
  if (static_cast<std::int64_t>(raw.positions.size()) != count) {
    fail(source, reader.line(), -1,
         section + ": the header says " + std::to_string(count) + " nodes, the blocks hold " +
             std::to_string(raw.positions.size()));
  }
  expect_gmsh_end(reader, source, section);
}

/// The physical groups of a .msh file's volumes: their names ($PhysicalNames) and each volume
/// entity's groups ($Entities), for the regions (issue 25).
struct GmshGroups {
  std::map<std::int64_t, std::string> volume_group_names;               // physical tag -> name
  std::map<std::int64_t, std::vector<std::int64_t>> volume_groups;      // volume entity tag -> physical tags
  std::vector<std::int64_t> tet_volume;                                 // per tet, its volume entity's tag
};

void read_gmsh_physical_names(LineReader& reader, const std::string& source, GmshGroups& groups) {
  const std::string section = "$PhysicalNames";
  const auto count = read_gmsh_ints(reader, source, "'numPhysicalNames'", 1, section)[0];
  for (std::int64_t k = 0; k < count; ++k) {
    if (!next_gmsh_data(reader)) fail(source, reader.line(), -1, section + ": truncated");
    const Item item{source, reader.line(), -1, section + ": "};
    if (reader.size() < 3) fail(source, reader.line(), -1, section + ": expected 'dimension physicalTag \"name\"'");
    const std::int64_t dimension = int_at(reader, 0, item);
    const std::int64_t tag = int_at(reader, 1, item);
    std::string name;
    for (std::size_t t = 2; t < reader.size(); ++t) {
      if (t > 2) name.push_back(' ');
      name.append(reader[t]);
    }
    if (name.size() >= 2 && name.front() == '"' && name.back() == '"') name = name.substr(1, name.size() - 2);
    if (dimension == 3) groups.volume_group_names[tag] = name;
  }
  expect_gmsh_end(reader, source, section);
}

void read_gmsh_entities(LineReader& reader, const std::string& source, GmshGroups& groups) {
  const std::string section = "$Entities";
  const auto counts = read_gmsh_ints(reader, source, "header 'numPoints numCurves numSurfaces numVolumes'", 4, section);
  for (std::size_t dimension = 0; dimension < 4; ++dimension) {
    // A point's line has its coordinates (3), the others their bounding box (6), before the physical tags.
    const std::size_t physical_count_at = 1 + (dimension == 0 ? 3 : 6);
    for (std::int64_t k = 0; k < counts[dimension]; ++k) {
      if (!next_gmsh_data(reader)) fail(source, reader.line(), -1, section + ": truncated");
      const Item item{source, reader.line(), -1, section + ": "};
      if (reader.size() <= physical_count_at) fail(source, reader.line(), -1, section + ": entity line too short");
      const std::int64_t physical_count = int_at(reader, physical_count_at, item);
      if (physical_count < 0 || reader.size() <= physical_count_at + static_cast<std::size_t>(physical_count)) {
        fail(source, reader.line(), -1, section + ": entity line shorter than its physical tags");
      }
      if (dimension != 3) continue;
      std::vector<std::int64_t>& tags = groups.volume_groups[int_at(reader, 0, item)];
      for (std::int64_t p = 0; p < physical_count; ++p) {
        tags.push_back(int_at(reader, physical_count_at + 1 + static_cast<std::size_t>(p), item));
      }
    }
  }
  expect_gmsh_end(reader, source, section);
}

/// Each tet's region: its volume's physical group, named by $PhysicalNames or else by its tag.
void resolve_gmsh_regions(const GmshGroups& groups, const std::string& source, RawMesh& raw) {
  bool any = false;
  for (const auto& [volume, tags] : groups.volume_groups) any = any || !tags.empty();
  if (!any) return;
  const auto name_of = [&](std::int64_t tag) {
    const auto named = groups.volume_group_names.find(tag);
    return named != groups.volume_group_names.end() ? named->second : std::to_string(tag);
  };
  raw.tet_regions.assign(raw.tets.size(), -1);
  for (std::size_t t = 0; t < raw.tets.size(); ++t) {
    const auto found = groups.volume_groups.find(groups.tet_volume[t]);
    if (found == groups.volume_groups.end() || found->second.empty()) continue;  // in no region: finish() says
    if (found->second.size() > 1) {
      fail(source, raw.element_lines[t], static_cast<int>(t),
           element_label(raw.element_numbers[t]) + "is in two regions, " + name_of(found->second[0]) + " and " +
               name_of(found->second[1]) + " (volume " + std::to_string(found->first) + " is in both physical groups)");
    }
    raw.tet_regions[t] = region_index(raw.regions, name_of(found->second[0]));
  }
}

void read_gmsh_elements(LineReader& reader, const std::string& source, RawMesh& raw,
                        const std::unordered_map<std::int64_t, int>& index_of_tag, std::size_t text_size,
                        GmshGroups& groups) {
  constexpr std::int64_t k_tet4 = 4;  // Gmsh element type of the 4-node tetrahedron
  const std::string section = "$Elements";
  const auto header =
      read_gmsh_ints(reader, source, "header 'numEntityBlocks numElements minElementTag maxElementTag'", 4, section);
  const std::int64_t blocks = header[0];
  const std::int64_t count = header[1];
  if (blocks < 0 || count < 0) {
    fail(source, reader.line(), -1, section + ": negative count in the header");
  }
  raw.tets.reserve(plausible_reserve(count, text_size));
  std::int64_t seen = 0;
  for (std::int64_t b = 0; b < blocks; ++b) {
    const auto block =
        read_gmsh_ints(reader, source, "entity block 'entityDim entityTag elementType numElementsInBlock'", 4, section);
    const std::int64_t type = block[2];
    const std::int64_t in_block = block[3];
    if (in_block < 0) {
      fail(source, reader.line(), -1, section + ": negative numElementsInBlock");
    }
    for (std::int64_t k = 0; k < in_block; ++k) {
      if (!next_gmsh_data(reader)) {
        fail(source, reader.line(), -1,
             section + ": truncated, the header says " + std::to_string(count) + " elements, found " +
                 std::to_string(seen));
      }
      ++seen;
      if (type != k_tet4) {
        continue;  // points, lines, triangles, higher-order elements: not part of the tet mesh
      }
      const int index = static_cast<int>(raw.tets.size());
      const Item first{source, reader.line(), index, "element: "};
      const std::int64_t tag = int_at(reader, 0, first);
      const Item item{source, reader.line(), index, element_label(tag)};
      expect_token_count(reader, 5, item, "elementTag n1 n2 n3 n4");
      std::array<std::int64_t, 4> tet{};
      for (std::size_t c = 0; c < 4; ++c) {
        const std::int64_t node = int_at(reader, c + 1, item);
        const auto found = index_of_tag.find(node);
        if (found == index_of_tag.end()) {
          fail(source, reader.line(), index, item.prefix + "node tag " + std::to_string(node) + " is not in $Nodes");
        }
        tet[c] = found->second;
      }
      raw.tets.push_back(tet);
      raw.element_lines.push_back(reader.line());
      raw.element_numbers.push_back(tag);
      groups.tet_volume.push_back(block[1]);
    }
  }
  if (seen != count) {
    fail(source, reader.line(), -1,
         section + ": the header says " + std::to_string(count) + " elements, the blocks hold " + std::to_string(seen));
  }
  expect_gmsh_end(reader, source, section);
  if (raw.tets.empty()) {
    fail(source, reader.line(), -1, section + ": no 4-node tetrahedra (element type 4)");
  }
}

void skip_gmsh_section(LineReader& reader, const std::string& source, const std::string& section) {
  const std::string end = "$End" + section.substr(1);
  const int begin = reader.line();
  while (reader.next()) {
    if (reader[0] == end) {
      return;
    }
  }
  fail(source, begin, -1, section + ": missing " + end);
}

}  // namespace

// ---------------------------------------------------------------------------------------------

void validate_tets(TetMesh& mesh, const std::string& source_name, const std::vector<int>& vertex_lines,
                   const std::vector<int>& element_lines, int index_base, MeshWarnings* warnings) {
  validate_impl(mesh, source_name, source_name, vertex_lines, element_lines, nullptr, index_base, warnings);
}

TetMesh parse_veg(std::string_view text, const std::string& source_name, MeshWarnings* warnings) {
  LineReader reader(text, '#', true);
  RawMesh raw;
  raw.vertex_base = 1;
  bool have_vertices = false;
  bool have_elements = false;
  VegRegions regions;
  while (reader.next()) {
    if (!is_veg_keyword(reader)) {
      fail(source_name, reader.line(), -1,
           "expected a *SECTION line, found '" + std::string(reader[0]) + "' (or a count in a header is too small)");
    }
    const std::string keyword = to_upper(reader[0]);
    if (keyword == "*VERTICES") {
      if (have_vertices) {
        fail(source_name, reader.line(), -1, "second *VERTICES section");
      }
      read_veg_vertices(reader, source_name, raw, text.size());
      have_vertices = true;
    } else if (keyword == "*ELEMENTS") {
      if (have_elements) {
        fail(source_name, reader.line(), -1, "second *ELEMENTS section");
      }
      read_veg_elements(reader, source_name, raw, text.size());
      have_elements = true;
    } else if (keyword == "*MATERIAL") {
      read_veg_material(reader, source_name, regions);
    } else if (keyword == "*SET") {
      read_veg_set(reader, source_name, regions);
    } else if (keyword == "*REGION") {
      read_veg_region(reader, source_name, regions);
    } else {
      // *INCLUDE, *CONSTRAINTS, ...: not read.
      while (next_veg_data(reader)) {
      }
    }
  }
  if (!have_vertices) {
    fail(source_name, 0, -1, "missing *VERTICES section");
  }
  if (!have_elements) {
    fail(source_name, 0, -1, "missing *ELEMENTS section");
  }
  resolve_veg_regions(regions, source_name, raw, warnings);
  return finish(std::move(raw), source_name, source_name, warnings);
}

TetMesh read_veg(const std::filesystem::path& path, MeshWarnings* warnings) {
  return parse_veg(read_text(path), path.string(), warnings);
}

TetMesh read_tetgen(const std::filesystem::path& path, MeshWarnings* warnings) {
  std::filesystem::path stem = path;
  const std::string extension = to_upper(path.extension().string());
  if (extension == ".NODE" || extension == ".ELE") {
    stem.replace_extension();
  }
  // The stem may itself contain dots (TetGen writes "mesh.1.node"), so append rather than replace.
  const std::filesystem::path node_path = stem.string() + ".node";
  const std::filesystem::path ele_path = stem.string() + ".ele";
  const std::string node_text = read_text(node_path);
  const std::string ele_text = read_text(ele_path);
  RawMesh raw;
  read_tetgen_nodes(node_text, node_path.string(), raw);
  read_tetgen_elements(ele_text, ele_path.string(), raw);
  return finish(std::move(raw), node_path.string(), ele_path.string(), warnings);
}

TetMesh parse_gmsh(std::string_view text, const std::string& source_name, MeshWarnings* warnings) {
  LineReader reader(text, '\0', false);
  RawMesh raw;
  raw.vertex_base = 0;  // node tags are mapped to indices while reading
  std::unordered_map<std::int64_t, int> index_of_tag;
  GmshGroups groups;
  bool have_format = false;
  bool have_nodes = false;
  bool have_elements = false;
  while (reader.next()) {
    if (!is_gmsh_section_line(reader)) {
      fail(source_name, reader.line(), -1,
           "expected a $Section line, found '" + std::string(reader[0]) + "' (or a count in a header is too small)");
    }
    const std::string section(reader[0]);
    if (section == "$MeshFormat") {
      read_gmsh_format(reader, source_name);
      have_format = true;
    } else if (!have_format) {
      fail(source_name, reader.line(), -1, "missing $MeshFormat before " + section);
    } else if (section == "$Nodes") {
      if (have_nodes) {
        fail(source_name, reader.line(), -1, "second $Nodes section");
      }
      read_gmsh_nodes(reader, source_name, raw, index_of_tag, text.size());
      have_nodes = true;
    } else if (section == "$Elements") {
      if (have_elements) {
        fail(source_name, reader.line(), -1, "second $Elements section");
      }
      if (!have_nodes) {
        fail(source_name, reader.line(), -1, "$Elements before $Nodes");
      }
      read_gmsh_elements(reader, source_name, raw, index_of_tag, text.size(), groups);
      have_elements = true;
    } else if (section == "$PhysicalNames") {
      read_gmsh_physical_names(reader, source_name, groups);
    } else if (section == "$Entities") {
      read_gmsh_entities(reader, source_name, groups);
    } else {
      skip_gmsh_section(reader, source_name, section);
    }
  }
  if (!have_format) {
    fail(source_name, 0, -1, "missing $MeshFormat section (not a Gmsh .msh file?)");
  }
  if (!have_nodes) {
    fail(source_name, 0, -1, "missing $Nodes section");
  }
  if (!have_elements) {
    fail(source_name, 0, -1, "missing $Elements section");
  }
  resolve_gmsh_regions(groups, source_name, raw);
  return finish(std::move(raw), source_name, source_name, warnings);
}

TetMesh read_gmsh(const std::filesystem::path& path, MeshWarnings* warnings) {
  return parse_gmsh(read_text(path), path.string(), warnings);
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

std::vector<int> read_bou(const std::filesystem::path& path, int vertex_count) {
  const std::string source = path.string();
  const std::string text = read_text(path);
  LineReader reader(text, '#', true);
  std::vector<int> ids;
  while (reader.next()) {
    const Item item{source, reader.line(), -1, ""};
    for (std::size_t k = 0; k < reader.size(); ++k) {
      const std::int64_t id = int_at(reader, k, item);
      if (id < 1 || id > vertex_count) {
        fail(source, reader.line(), -1,
             "vertex " + std::to_string(id) + " out of range [1, " + std::to_string(vertex_count) + "]");
      }
      ids.push_back(static_cast<int>(id - 1));
    }
  }
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return ids;
}

namespace {

// The surface of a solid: every edge run by exactly two triangles, once each way.
void check_closed_manifold(const TriangleSurface& surface, const std::string& source,
                           const std::vector<int>& triangle_lines) {
  std::map<std::pair<int, int>, std::pair<int, int>> runs;  // edge (lower first) -> runs a->b, b->a
  for (size_t t = 0; t < surface.triangles.size(); ++t) {
    const auto& tri = surface.triangles[t];
    for (size_t k = 0; k < 3; ++k) {
      const int a = tri[k], b = tri[(k + 1) % 3];
      auto& [forward, backward] = runs[{std::min(a, b), std::max(a, b)}];
      (a < b ? forward : backward) += 1;
      const std::string edge = "triangle " + std::to_string(t + 1) + ": edge " + std::to_string(a + 1) + "-" +
                               std::to_string(b + 1);
      if (forward + backward > 2) {
        fail(source, triangle_lines[t], static_cast<int>(t + 1), edge + " is shared by more than two triangles (not manifold)");
      }
      if (forward > 1 || backward > 1) {
        fail(source, triangle_lines[t], static_cast<int>(t + 1),
             edge + " is run the same way by two triangles (not consistently oriented)");
      }
    }
  }
  for (const auto& [edge, counts] : runs) {
    if (counts.first + counts.second != 2) {
      fail(source, 0, 0,
           "edge " + std::to_string(edge.first + 1) + "-" + std::to_string(edge.second + 1) +
               " borders a single triangle (the surface is not closed)");
    }
  }
}

}  // namespace

TriangleSurface parse_obj(std::string_view text, const std::string& source_name) {
  TriangleSurface surface;
  surface.source_name = source_name;
  std::vector<int> triangle_lines;
  LineReader reader(text, '#', false);
  while (reader.next()) {
    const int line = reader.line();
    if (reader[0] == "v") {
      const std::string vertex = "vertex " + std::to_string(surface.vertices_m.size() + 1);
      if (reader.size() < 4) fail(source_name, line, 0, vertex + ": fewer than 3 coordinates");
      Eigen::Vector3d p;
      for (std::size_t a = 0; a < 3; ++a) {
        const std::optional<double> value = parse_double(reader[a + 1]);
        if (!value || !std::isfinite(*value)) {
          fail(source_name, line, 0, vertex + ": coordinate '" + std::string(reader[a + 1]) + "' is not a finite number");
        }
        p(static_cast<Eigen::Index>(a)) = *value;
      }
      surface.vertices_m.push_back(p);
    } else if (reader[0] == "f") {
      const int face = static_cast<int>(triangle_lines.size()) + 1;
      if (reader.size() < 4) fail(source_name, line, 0, "face with fewer than 3 corners");
      std::vector<int> corners;
      const auto count = static_cast<std::int64_t>(surface.vertices_m.size());
      for (std::size_t k = 1; k < reader.size(); ++k) {
        const std::optional<std::int64_t> index = parse_int(reader[k].substr(0, reader[k].find('/')));
        const std::int64_t resolved = index && *index < 0 ? count + *index : (index ? *index - 1 : -1);
        if (!index || *index == 0 || resolved < 0 || resolved >= count) {
          fail(source_name, line, 0,
               "face corner '" + std::string(reader[k]) + "' is not a vertex (" + std::to_string(count) + " read so far)");
        }
        corners.push_back(static_cast<int>(resolved));
      }
      for (size_t a = 0; a < corners.size(); ++a) {
        for (size_t b = a + 1; b < corners.size(); ++b) {
          if (corners[a] == corners[b]) {
            fail(source_name, line, 0, "face " + std::to_string(face) + " repeats vertex " + std::to_string(corners[a] + 1));
          }
        }
      }
      for (size_t k = 1; k + 1 < corners.size(); ++k) {
        surface.triangles.push_back({corners[0], corners[k], corners[k + 1]});
        triangle_lines.push_back(line);
      }
    }
  }
  if (surface.triangles.empty()) fail(source_name, 0, 0, "no triangle (no 'f' record)");
  check_closed_manifold(surface, source_name, triangle_lines);
  return surface;
}

TriangleSurface read_obj(const std::filesystem::path& path) { return parse_obj(read_text(path), path.string()); }

}  // namespace tissue
