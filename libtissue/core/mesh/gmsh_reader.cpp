// Gmsh .msh 4.1 ASCII tet meshes, with the regions of their volumes' physical groups (mesh_io.hpp).
#include "core/mesh/mesh_io.hpp"

#include "core/mesh/mesh_io_detail.hpp"

#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace tissue {

using namespace mesh_io_detail;  // NOLINT(google-build-using-namespace): the readers' own helpers

namespace {

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

// A $Nodes or $Elements header: its block and item counts, refused when negative.
std::pair<std::int64_t, std::int64_t> read_gmsh_section_header(LineReader& reader, const std::string& source,
                                                               const std::string& what, const std::string& section) {
  const auto header = read_gmsh_ints(reader, source, what, 4, section);
  if (header[0] < 0 || header[1] < 0) fail(source, reader.line(), -1, section + ": negative count in the header");
  return {header[0], header[1]};
}

void read_gmsh_nodes(LineReader& reader, const std::string& source, RawMesh& raw,
                     std::unordered_map<std::int64_t, int>& index_of_tag, std::size_t text_size) {
  const std::string section = "$Nodes";
  const auto [blocks, count] =
      read_gmsh_section_header(reader, source, "header 'numEntityBlocks numNodes minNodeTag maxNodeTag'", section);
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
  std::map<std::int64_t, std::string> volume_group_names;           // physical tag -> name
  std::map<std::int64_t, std::vector<std::int64_t>> volume_groups;  // volume entity tag -> physical tags
  std::vector<std::int64_t> tet_volume;                             // per tet, its volume entity's tag
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
  const auto [blocks, count] = read_gmsh_section_header(
      reader, source, "header 'numEntityBlocks numElements minElementTag maxElementTag'", section);
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

}  // namespace tissue
