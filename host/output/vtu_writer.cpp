// vtu_writer.cpp - VTK XML UnstructuredGrid writer (VTK file formats, "XML File Formats").
#include "output/vtu_writer.hpp"

#include <array>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace tissue::host {
namespace {

constexpr std::uint8_t VTK_TRIANGLE = 5;
// Values per line of the long scalar arrays (offsets, types, cut_face).
constexpr std::size_t VALUES_PER_LINE = 16;

/// Appends the shortest decimal that reads back as @p value ("C" locale regardless of the global one).
void append_number(std::string& out, double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), static_cast<std::size_t>(result.ptr - buffer.data()));
}

void append_number(std::string& out, std::uint64_t value) {
  std::array<char, 24> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), static_cast<std::size_t>(result.ptr - buffer.data()));
}

void open_array(std::string& out, std::string_view indent, std::string_view type, std::string_view name,
                std::size_t components, std::string_view extra = {}) {
  out += indent;
  out += "<DataArray type=\"";
  out += type;
  out += "\" Name=\"";
  out += name;
  out += '"';
  if (components != 1) {
    out += " NumberOfComponents=\"";
    append_number(out, std::uint64_t{components});
    out += '"';
  }
  out += extra;
  out += " format=\"ascii\">\n";
}

void close_array(std::string& out, std::string_view indent) {
  out += indent;
  out += "</DataArray>\n";
}

/// One-tuple Float64 field-data array.
void field_array(std::string& out, std::string_view name, const double* values, std::size_t count) {
  constexpr std::string_view INDENT = "      ";
  open_array(out, INDENT, "Float64", name, count, " NumberOfTuples=\"1\"");
  out += INDENT;
  out += "  ";
  for (std::size_t i = 0; i < count; ++i) {
    if (i != 0) out += ' ';
    append_number(out, values[i]);
  }
  out += '\n';
  close_array(out, INDENT);
}

/// Writes value(i) for i < count, VALUES_PER_LINE to a line.
template <typename Value>
void scalar_lines(std::string& out, std::string_view indent, std::size_t count, Value value) {
  for (std::size_t i = 0; i < count; ++i) {
    if (i % VALUES_PER_LINE == 0) {
      out += indent;
    } else {
      out += ' ';
    }
    append_number(out, std::uint64_t{value(i)});
    if (i % VALUES_PER_LINE == VALUES_PER_LINE - 1 || i + 1 == count) out += '\n';
  }
}

}  // namespace

std::string vtu_document(const SurfaceFrame& frame) {
  validate_surface_frame(frame, "vtu_document");
  const std::size_t vertex_count = frame.vertex_count();
  const std::size_t triangle_count = frame.triangle_count();

  std::string out;
  // About 60 characters per vertex and 40 per triangle; a guess, not a bound.
  out.reserve(1024 + 60 * vertex_count + 40 * triangle_count);
  out += "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  out += "  <UnstructuredGrid>\n";

  out += "    <FieldData>\n";
  field_array(out, "TimeValue", &frame.time_s, 1);
  if (frame.has_tool) {
    field_array(out, "tool_tip_m", frame.tool_tip_m.data(), 3);
    field_array(out, "tool_handle_m", frame.tool_handle_m.data(), 3);
    out += "      <DataArray type=\"Int32\" Name=\"tool_mode\" NumberOfTuples=\"1\" format=\"ascii\">\n        ";
    append_number(out, static_cast<std::uint64_t>(frame.tool_mode));  // validated to be 0..2
    out += "\n      </DataArray>\n";
  }
  if (frame.contact_active) {
    field_array(out, "contact_point_m", frame.contact_point_m.data(), 3);
    field_array(out, "force_n", frame.force_n.data(), 3);
  }
  out += "    </FieldData>\n";

  out += "    <Piece NumberOfPoints=\"";
  append_number(out, std::uint64_t{vertex_count});
  out += "\" NumberOfCells=\"";
  append_number(out, std::uint64_t{triangle_count});
  out += "\">\n";

  constexpr std::string_view ARRAY_INDENT = "        ";
  constexpr std::string_view VALUE_INDENT = "          ";

  out += "      <CellData Scalars=\"cut_face\">\n";
  open_array(out, ARRAY_INDENT, "UInt8", "cut_face", 1);
  scalar_lines(out, VALUE_INDENT, triangle_count,
               [&frame](std::size_t t) { return t < frame.mesh_triangle_count ? 0U : 1U; });
  close_array(out, ARRAY_INDENT);
  out += "      </CellData>\n";

  out += "      <Points>\n";
  open_array(out, ARRAY_INDENT, "Float64", "Points", 3);
  for (std::size_t v = 0; v < vertex_count; ++v) {
    out += VALUE_INDENT;
    for (std::size_t c = 0; c < 3; ++c) {
      if (c != 0) out += ' ';
      append_number(out, frame.positions_m[3 * v + c]);
    }
    out += '\n';
  }
  close_array(out, ARRAY_INDENT);
  out += "      </Points>\n";

  out += "      <Cells>\n";
  open_array(out, ARRAY_INDENT, "Int64", "connectivity", 1);
  for (std::size_t t = 0; t < triangle_count; ++t) {
    out += VALUE_INDENT;
    for (std::size_t c = 0; c < 3; ++c) {
      if (c != 0) out += ' ';
      append_number(out, std::uint64_t{frame.triangles[3 * t + c]});
    }
    out += '\n';
  }
  close_array(out, ARRAY_INDENT);
  // VTK's offsets are where each cell's connectivity ends.
  open_array(out, ARRAY_INDENT, "Int64", "offsets", 1);
  scalar_lines(out, VALUE_INDENT, triangle_count, [](std::size_t t) { return std::uint64_t{3 * (t + 1)}; });
  close_array(out, ARRAY_INDENT);
  open_array(out, ARRAY_INDENT, "UInt8", "types", 1);
  scalar_lines(out, VALUE_INDENT, triangle_count, [](std::size_t) { return VTK_TRIANGLE; });
  close_array(out, ARRAY_INDENT);
  out += "      </Cells>\n";

  out += "    </Piece>\n";
  out += "  </UnstructuredGrid>\n";
  out += "</VTKFile>\n";
  return out;
}

void write_vtu(const std::filesystem::path& path, const SurfaceFrame& frame) {
  write_output_file(path, vtu_document(frame));
}

}  // namespace tissue::host
