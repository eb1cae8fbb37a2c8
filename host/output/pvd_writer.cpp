// pvd_writer.cpp - ParaView data (.pvd) collection writer.
#include "output/pvd_writer.hpp"

#include "output/surface_frame.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <utility>

namespace tissue::host {
namespace {

void append_xml_escaped(std::string& out, std::string_view text) {
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
}

}  // namespace

std::string frame_file_name(std::string_view stem, std::size_t index) {
  std::array<char, 32> digits{};
  const int length = std::snprintf(digits.data(), digits.size(), "%06zu", index);
  std::string name(stem);
  name += '_';
  name.append(digits.data(), static_cast<std::size_t>(length));
  name += ".vtu";
  return name;
}

void PvdWriter::add(double time_s, std::string relative_file) {
  if (!std::isfinite(time_s)) throw OutputError("PvdWriter::add: time of " + relative_file + " is not finite");
  if (!m_entries.empty() && !(time_s > m_entries.back().time_s)) {
    throw OutputError("PvdWriter::add: time " + std::to_string(time_s) + " of " + relative_file +
                      " is not after the previous frame's " + std::to_string(m_entries.back().time_s));
  }
  if (relative_file.empty()) throw OutputError("PvdWriter::add: empty file name");
  if (std::filesystem::path(relative_file).is_absolute()) {
    throw OutputError("PvdWriter::add: " + relative_file + " is absolute; give it relative to the .pvd");
  }
  for (const char c : relative_file) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      throw OutputError("PvdWriter::add: file name " + relative_file + " holds a control character");
    }
  }
  m_entries.push_back({time_s, std::move(relative_file)});
}

std::string PvdWriter::document() const {
  std::string out;
  out += "<?xml version=\"1.0\"?>\n";
  out += "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n";
  out += "  <Collection>\n";
  for (const Entry& entry : m_entries) {
    std::array<char, 32> time{};
    const auto result = std::to_chars(time.data(), time.data() + time.size(), entry.time_s);
    out += "    <DataSet timestep=\"";
    out.append(time.data(), static_cast<std::size_t>(result.ptr - time.data()));
    out += "\" group=\"\" part=\"0\" file=\"";
    append_xml_escaped(out, entry.file);
    out += "\"/>\n";
  }
  out += "  </Collection>\n";
  out += "</VTKFile>\n";
  return out;
}

void PvdWriter::write(const std::filesystem::path& path) const { write_output_file(path, document()); }

}  // namespace tissue::host
