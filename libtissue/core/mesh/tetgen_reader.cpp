// TetGen .node / .ele tet meshes, the first .ele attribute naming the region (mesh_io.hpp).
#include "core/mesh/mesh_io.hpp"

#include "core/mesh/mesh_io_detail.hpp"

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>

namespace tissue {

using namespace mesh_io_detail;  // NOLINT(google-build-using-namespace): the readers' own helpers

namespace {

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

}  // namespace

TetMesh read_tetgen(const std::filesystem::path& path, MeshWarnings* warnings) {
  std::filesystem::path stem = path;
  const std::string extension = to_upper(path.extension().string());
  if (extension == ".NODE" || extension == ".ELE") {
    stem.replace_extension();
  }
  // The stem may itself contain dots (TetGen writes "mesh.1.node"), so append rather than replace.
  const std::filesystem::path node_path = stem.string() + ".node";
  const std::filesystem::path ele_path = stem.string() + ".ele";
  return parse_tetgen(read_text(node_path), read_text(ele_path), node_path.string(), ele_path.string(), warnings);
}

TetMesh parse_tetgen(std::string_view node_text, std::string_view ele_text, const std::string& node_name,
                     const std::string& ele_name, MeshWarnings* warnings) {
  RawMesh raw;
  read_tetgen_nodes(node_text, node_name, raw);
  read_tetgen_elements(ele_text, ele_name, raw);
  return finish(std::move(raw), node_name, ele_name, warnings);
}

}  // namespace tissue
