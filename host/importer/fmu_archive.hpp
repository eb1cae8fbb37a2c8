// fmu_archive.hpp - an .fmu file unpacked into a private temporary directory.
//
// An FMU is a zip archive (FMI 3.0 section 2.5). The importer extracts it once, reads
// modelDescription.xml, loads binaries/<platform>/<modelIdentifier>.so and hands the FMU the
// absolute path of resources/. The directory lives exactly as long as the FmuArchive object.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace tissue::host {

/// Platform tuple of the FMU binaries this importer loads (FMI 3.0 section 2.5.1.1).
inline constexpr std::string_view FMI3_PLATFORM = "x86_64-linux";

/**
 * An FMU extracted into a fresh directory under the system temporary directory (mkdtemp),
 * removed recursively by the destructor. Movable, not copyable.
 *
 * The constructor refuses, with an FmuError naming the file: a missing file, a file that is
 * not a zip archive, an archive without modelDescription.xml at its root, and any entry with
 * an absolute path or a ".." component (zip-slip). Entry names are all checked before
 * anything is written.
 */
class FmuArchive {
 public:
  /// Extracts @p fmu_path; throws FmuError on any of the refusals above or an I/O failure.
  explicit FmuArchive(const std::filesystem::path& fmu_path);
  ~FmuArchive();

  FmuArchive(const FmuArchive&) = delete;
  FmuArchive& operator=(const FmuArchive&) = delete;
  FmuArchive(FmuArchive&& other) noexcept;
  FmuArchive& operator=(FmuArchive&& other) noexcept;

  /// The .fmu file this archive was extracted from, as given to the constructor.
  [[nodiscard]] const std::filesystem::path& fmu_path() const { return m_fmu_path; }
  /// Absolute path of the directory the FMU was unpacked into (empty after a move).
  [[nodiscard]] const std::filesystem::path& directory() const { return m_directory; }
  /// directory()/modelDescription.xml.
  [[nodiscard]] std::filesystem::path model_description_path() const;
  /// directory()/resources (it need not exist: an FMU without resources is valid).
  [[nodiscard]] std::filesystem::path resources_directory() const;
  /**
   * The resourcePath argument of fmi3Instantiate*: the absolute filesystem path of the
   * resources directory ending with '/' (FMI 3.0 section 2.3.1).
   */
  [[nodiscard]] std::string resource_path() const;
  /// directory()/binaries/x86_64-linux/<model_identifier>.so.
  [[nodiscard]] std::filesystem::path binary_path(std::string_view model_identifier) const;

 private:
  void remove_directory() noexcept;

  std::filesystem::path m_fmu_path;
  std::filesystem::path m_directory;
};

/// Reads a whole file into a string; throws FmuError naming the file if it cannot be read.
[[nodiscard]] std::string read_text_file(const std::filesystem::path& path);

}  // namespace tissue::host
