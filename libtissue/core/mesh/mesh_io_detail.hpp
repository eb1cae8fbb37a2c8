// Private to core/mesh: what the mesh readers (mesh_io.cpp and the *_reader.cpp of each format)
// share: the line reader, token parsing that fails with file and line, and the RawMesh they fill.
#pragma once

#include "core/mesh/mesh_io.hpp"

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tissue::mesh_io_detail {

/// "<source>:<line>", or the source alone when line is 0.
std::string location(const std::string& source, int line);

/// Throws the MeshError every reader uses: "<source>:<line>: <what>" (line omitted when 0).
[[noreturn]] void fail(const std::string& source, int line, int element, const std::string& what);

/// The whole file; MeshError if it cannot be opened or read.
std::string read_text(const std::filesystem::path& path);

std::string to_upper(std::string_view text);

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

std::optional<std::int64_t> parse_int(std::string_view token);
/// Overflow reads as infinity (refused as a non-finite coordinate), underflow as 0.
std::optional<double> parse_double(std::string_view token);

/// Context for messages about one item of a file: where it is and how the file numbers it.
struct Item {
  const std::string& source;
  int line;
  int element;         ///< 0-based tet index for MeshError, -1 if not an element
  std::string prefix;  ///< e.g. "element 12: " or "vertex 3: " or "*VERTICES header: "
};

std::int64_t int_at(const LineReader& reader, std::size_t k, const Item& item);
double double_at(const LineReader& reader, std::size_t k, const Item& item);
void expect_token_count(const LineReader& reader, std::size_t expected, const Item& item, const char* layout);
/// Reads three coordinates starting at token k and refuses NaN/Inf.
Eigen::Vector3d position_at(const LineReader& reader, std::size_t k, const Item& item);

/// Element counts in headers are used to reserve memory; a corrupt header must not make us
/// allocate gigabytes before the truncation is noticed, so a count is only trusted up to what
/// the text could possibly hold (one item per two characters).
std::size_t plausible_reserve(std::int64_t count, std::size_t text_size);

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
int region_index(std::vector<MeshRegion>& regions, const std::string& name);

/// "element <number>: ", the prefix of messages about an element.
std::string element_label(std::int64_t number);

/// Maps the file's vertex numbers to 0-based indices (refusing those out of range) and validates.
TetMesh finish(RawMesh raw, const std::string& vertex_source, const std::string& element_source,
               MeshWarnings* warnings);

}  // namespace tissue::mesh_io_detail
