// host_test_support.hpp - helpers of the host tests: a private temporary directory, zip files
// written with libzip, and a minimal FMI 3.0 model description to build on.
#pragma once

#include <zip.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace tissue::host::test {

/// A fresh directory under the system temporary directory, removed with its content.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "tissue-host-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("mkdtemp failed");
    }
    m_path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(m_path, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  TempDir(TempDir&&) = delete;
  TempDir& operator=(TempDir&&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return m_path; }

 private:
  std::filesystem::path m_path;
};

/// One entry of a test zip: a name and its content; a name ending in '/' is a directory.
struct ZipEntry {
  std::string name;
  std::string content;
};

/// Writes @p entries into a new zip archive at @p path with libzip (names stored verbatim).
inline void write_zip(const std::filesystem::path& path, const std::vector<ZipEntry>& entries) {
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  ASSERT_NE(archive, nullptr) << "zip_open " << path << " failed with libzip error " << error;
  for (const ZipEntry& entry : entries) {
    if (!entry.name.empty() && entry.name.back() == '/') {
      ASSERT_GE(zip_dir_add(archive, entry.name.c_str(), ZIP_FL_ENC_UTF_8), 0) << zip_strerror(archive);
      continue;
    }
    zip_source_t* source = zip_source_buffer(archive, entry.content.data(), entry.content.size(), 0);
    ASSERT_NE(source, nullptr) << zip_strerror(archive);
    if (zip_file_add(archive, entry.name.c_str(), source, ZIP_FL_OVERWRITE | ZIP_FL_ENC_UTF_8) < 0) {
      zip_source_free(source);
      FAIL() << "zip_file_add '" << entry.name << "': " << zip_strerror(archive);
    }
  }
  ASSERT_EQ(zip_close(archive), 0) << "zip_close " << path;
}

inline void write_file(const std::filesystem::path& path, const std::string& content) {
  std::ofstream out(path, std::ios::binary);
  out << content;
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A valid FMI 3.0 Co-Simulation model description with @p variables inside <ModelVariables>
/// after the independent variable "time" (valueReference 0), and @p extra after <CoSimulation>.
inline std::string model_description_xml(
    const std::string& variables = "", const std::string& extra = "",
    const std::string& co_simulation = R"(<CoSimulation modelIdentifier="Minimal"/>)",
    const std::string& fmi_version = "3.0") {
  return R"(<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion=")" +
         fmi_version + R"(" modelName="Minimal" instantiationToken="{8c4e810f-3df3-4a00-8276-176fa3c9f000}">
  )" + co_simulation +
         "\n  " + extra + R"(
  <ModelVariables>
    <Float64 name="time" valueReference="0" causality="independent" variability="continuous"/>
    )" + variables +
         R"(
  </ModelVariables>
</fmiModelDescription>
)";
}

}  // namespace tissue::host::test
