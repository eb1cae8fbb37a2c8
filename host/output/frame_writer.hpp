// FrameWriter: a session's surface frames as frames/frame_*.vtu in the output folder, indexed by
// surface.pvd for ParaView.
#pragma once

#include "output/pvd_writer.hpp"
#include "output/surface_frame.hpp"
#include "output/vtu_writer.hpp"

#include <cstddef>
#include <filesystem>
#include <string>

namespace tissue::host {

class FrameWriter {
 public:
  explicit FrameWriter(const std::filesystem::path& output_dir) : m_dir(output_dir) {
    std::filesystem::create_directories(m_dir / "frames");
  }
  void write(const SurfaceFrame& frame) {
    const std::string name = frame_file_name("frame", m_pvd.size());
    write_vtu(m_dir / "frames" / name, frame);
    m_pvd.add(frame.time_s, "frames/" + name);
  }
  void finish() const { m_pvd.write(m_dir / "surface.pvd"); }
  [[nodiscard]] std::size_t count() const { return m_pvd.size(); }

 private:
  std::filesystem::path m_dir;
  PvdWriter m_pvd;
};

}  // namespace tissue::host
