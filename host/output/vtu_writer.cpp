// vtu_writer.cpp - VTK XML UnstructuredGrid writer (VTK file formats, "XML File Formats").
#include "output/vtu_writer.hpp"

#include "output/session_log.hpp"

#include <array>
#include <bit>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>
#include <vector>

namespace tissue::host {
namespace {

constexpr std::uint8_t VTK_TRIANGLE = 5;

void append_integer(std::string& out, std::uint64_t value) {
  std::array<char, 24> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  out.append(buffer.data(), static_cast<std::size_t>(result.ptr - buffer.data()));
}

// VTK's "binary" DataArray (XML formats, version 0.1, header_type UInt32): base64 of the byte
// count (UInt32, little-endian) followed by the values' own little-endian bytes. An organ's frame
// (41k points, 82k triangles) is 3.2 MB this way against 6.4 MB of shortest decimals, and encodes
// in a fraction of their time: the recording shares two cores with the dynamics (issue 42).
constexpr std::string_view BASE64_DIGITS = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

void append_base64(std::string& out, const std::vector<std::uint8_t>& bytes) {
  const std::size_t n = bytes.size();
  const std::size_t start = out.size();
  out.resize(start + 4 * ((n + 2) / 3));
  char* digit = out.data() + start;
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    const std::uint32_t triple = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    *digit++ = BASE64_DIGITS[(triple >> 18) & 63U];
    *digit++ = BASE64_DIGITS[(triple >> 12) & 63U];
    *digit++ = BASE64_DIGITS[(triple >> 6) & 63U];
    *digit++ = BASE64_DIGITS[triple & 63U];
  }
  if (i < n) {
    const std::uint32_t triple = (std::uint32_t{bytes[i]} << 16) | (i + 1 < n ? std::uint32_t{bytes[i + 1]} << 8 : 0U);
    *digit++ = BASE64_DIGITS[(triple >> 18) & 63U];
    *digit++ = BASE64_DIGITS[(triple >> 12) & 63U];
    *digit++ = i + 1 < n ? BASE64_DIGITS[(triple >> 6) & 63U] : '=';
    *digit = '=';
  }
}

/// Appends @p value's bytes, little-endian (the host's order on every platform we build for,
/// checked at compile time below).
template <typename Value>
void append_bytes(std::vector<std::uint8_t>& bytes, Value value) {
  static_assert(std::endian::native == std::endian::little, "the VTU writer writes the host's bytes as LittleEndian");
  std::array<std::uint8_t, sizeof(Value)> raw{};
  std::memcpy(raw.data(), &value, sizeof(Value));
  bytes.insert(bytes.end(), raw.begin(), raw.end());
}

void open_array(std::string& out, std::string_view indent, std::string_view type, std::string_view name,
                std::size_t components, std::string_view extra = {}, std::string_view format = "ascii") {
  out += indent;
  out += "<DataArray type=\"";
  out += type;
  out += "\" Name=\"";
  out += name;
  out += '"';
  if (components != 1) {
    out += " NumberOfComponents=\"";
    append_integer(out, std::uint64_t{components});
    out += '"';
  }
  out += extra;
  out += " format=\"";
  out += format;
  out += "\">\n";
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

/// A DataArray of value(i), i < count, in VTK's binary format (one base64 line).
template <typename Stored, typename Value>
void binary_array(std::string& out, std::string_view type, std::string_view name, std::size_t components,
                  std::size_t count, Value value) {
  constexpr std::string_view ARRAY_INDENT = "        ";
  open_array(out, ARRAY_INDENT, type, name, components, {}, "binary");
  std::vector<std::uint8_t> bytes;
  bytes.reserve(sizeof(std::uint32_t) + count * sizeof(Stored));
  append_bytes(bytes, static_cast<std::uint32_t>(count * sizeof(Stored)));
  for (std::size_t i = 0; i < count; ++i) append_bytes(bytes, static_cast<Stored>(value(i)));
  out += "          ";
  append_base64(out, bytes);
  out += '\n';
  close_array(out, ARRAY_INDENT);
}

}  // namespace

std::string vtu_document(const SurfaceFrame& frame) {
  validate_surface_frame(frame, "vtu_document");
  const std::size_t vertex_count = frame.vertex_count();
  const std::size_t triangle_count = frame.triangle_count();

  std::string out;
  // Base64 of 24 bytes per vertex and 18 per triangle, a third more.
  out.reserve(1024 + 32 * vertex_count + 24 * triangle_count);
  out += "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  out += "  <UnstructuredGrid>\n";

  out += "    <FieldData>\n";
  field_array(out, "TimeValue", &frame.time_s, 1);
  if (frame.has_tool) {
    field_array(out, "tool_tip_m", frame.tool_tip_m.data(), 3);
    field_array(out, "tool_handle_m", frame.tool_handle_m.data(), 3);
    out += "      <DataArray type=\"Int32\" Name=\"tool_mode\" NumberOfTuples=\"1\" format=\"ascii\">\n        ";
    append_integer(out, static_cast<std::uint64_t>(frame.tool_mode));  // validated to be 0..2
    out += "\n      </DataArray>\n";
  }
  if (frame.contact_active) {
    field_array(out, "contact_point_m", frame.contact_point_m.data(), 3);
    field_array(out, "force_n", frame.force_n.data(), 3);
  }
  out += "    </FieldData>\n";

  out += "    <Piece NumberOfPoints=\"";
  append_integer(out, std::uint64_t{vertex_count});
  out += "\" NumberOfCells=\"";
  append_integer(out, std::uint64_t{triangle_count});
  out += "\">\n";

  out += "      <CellData Scalars=\"cut_face\">\n";
  binary_array<std::uint8_t>(out, "UInt8", "cut_face", 1, triangle_count,
                             [&frame](std::size_t t) { return t < frame.mesh_triangle_count ? 0U : 1U; });
  out += "      </CellData>\n";

  out += "      <Points>\n";
  binary_array<double>(out, "Float64", "Points", 3, 3 * vertex_count,
                       [&frame](std::size_t i) { return frame.positions_m[i]; });
  out += "      </Points>\n";

  // Int32 indices: a frame's points number far below 2^31 (validate_surface_frame checks the
  // triangles' corners against the points). VTK's offsets are where each cell's connectivity ends.
  out += "      <Cells>\n";
  binary_array<std::int32_t>(out, "Int32", "connectivity", 1, 3 * triangle_count,
                             [&frame](std::size_t i) { return frame.triangles[i]; });
  binary_array<std::int32_t>(out, "Int32", "offsets", 1, triangle_count,
                             [](std::size_t t) { return 3 * (t + 1); });
  binary_array<std::uint8_t>(out, "UInt8", "types", 1, triangle_count, [](std::size_t) { return VTK_TRIANGLE; });
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
