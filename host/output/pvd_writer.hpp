// pvd_writer.hpp - a ParaView collection (.pvd) indexing the .vtu frames of a run by time, so
// that ParaView opens the whole run as one time series.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tissue::host {

/// "<stem>_<index as 6 or more digits>.vtu", e.g. frame_file_name("frame", 42) == "frame_000042.vtu".
[[nodiscard]] std::string frame_file_name(std::string_view stem, std::size_t index);

/**
 * The frames of one run, in time order. The document lists each as
 * <DataSet timestep="t" group="" part="0" file="f"/> with t in shortest round-trip decimal, so
 * that equal collections give byte-identical files. File names are relative to the .pvd's
 * directory (ParaView resolves them so), XML-escaped.
 */
class PvdWriter {
 public:
  /**
   * Appends a frame. Throws OutputError if @p time_s is not finite or not greater than the last
   * frame's time, or @p relative_file is empty, absolute, or holds a control character.
   */
  void add(double time_s, std::string relative_file);

  [[nodiscard]] std::size_t size() const { return m_entries.size(); }

  /// The .pvd document (VTK XML "Collection").
  [[nodiscard]] std::string document() const;

  /// Writes document() to @p path (replacing it whole, so it can be rewritten after every frame).
  void write(const std::filesystem::path& path) const;

 private:
  struct Entry {
    double time_s;
    std::string file;
  };
  std::vector<Entry> m_entries;
};

}  // namespace tissue::host
