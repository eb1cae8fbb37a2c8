// Vega .veg tet meshes, with their materials, sets and regions (issue 25), and Vega .bou lists of
// fixed vertices (mesh_io.hpp).
#include "core/mesh/mesh_io.hpp"

#include "core/mesh/mesh_io_detail.hpp"

#include <algorithm>
#include <cstdint>
#include <map>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace tissue {

using namespace mesh_io_detail;  // NOLINT(google-build-using-namespace): the readers' own helpers

namespace {

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
             prefix + "element " + std::to_string(element) + " is in two regions, " +
                 raw.regions[static_cast<std::size_t>(region)].name + " and " + assignment.set);
      }
      region = index;
    }
  }
}

}  // namespace

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

std::vector<int> read_bou(const std::filesystem::path& path, int vertex_count) {
  return parse_bou(read_text(path), vertex_count, path.string());
}

std::vector<int> parse_bou(std::string_view text, int vertex_count, const std::string& source) {
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

}  // namespace tissue
