// test_fmu_archive.cpp - FmuArchive on zip files the test writes: extraction, cleanup, refusals.
#include "host_test_support.hpp"
#include "importer/fmu_archive.hpp"
#include "importer/fmu_error.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <utility>

namespace tissue::host {
namespace {

using test::TempDir;
using test::write_zip;
using test::ZipEntry;

/**
 * Points TMPDIR at a private directory for the test, so that it can check that the archive is
 * extracted there and that nothing is left behind, neither after destruction nor after a refusal.
 */
class FmuArchiveTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const char* previous = std::getenv("TMPDIR");
    m_previous_tmpdir = previous == nullptr ? std::string() : std::string(previous);
    m_had_tmpdir = previous != nullptr;
    m_extract_root = m_files.path() / "tmp";
    std::filesystem::create_directory(m_extract_root);
    ::setenv("TMPDIR", m_extract_root.c_str(), 1);
  }
  void TearDown() override {
    if (m_had_tmpdir) {
      ::setenv("TMPDIR", m_previous_tmpdir.c_str(), 1);
    } else {
      ::unsetenv("TMPDIR");
    }
  }

  /// Number of entries left in the extraction root.
  [[nodiscard]] std::size_t leftovers() const {
    std::size_t count = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(m_extract_root)) {
      ++count;
    }
    return count;
  }

  /// Expects FmuArchive(@p path) to throw an FmuError whose message has the path and @p part.
  void expect_refused(const std::filesystem::path& path, const std::string& part) {
    try {
      const FmuArchive archive(path);
      ADD_FAILURE() << "accepted " << path << ", expected a refusal mentioning '" << part << "'";
    } catch (const FmuError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find(path.string()), std::string::npos) << "'" << message << "' does not name the file";
      EXPECT_NE(message.find(part), std::string::npos) << "'" << message << "' does not mention '" << part << "'";
    }
    EXPECT_EQ(leftovers(), 0U) << "a refused archive left files behind";
  }

  TempDir m_files;
  std::filesystem::path m_extract_root;
  std::string m_previous_tmpdir;
  bool m_had_tmpdir = false;
};

TEST_F(FmuArchiveTest, ExtractsEveryEntryAndRemovesTheDirectory) {
  const std::filesystem::path fmu = m_files.path() / "Valid.fmu";
  ASSERT_NO_FATAL_FAILURE(write_zip(fmu, {{"modelDescription.xml", "<fmiModelDescription/>"},
                                          {"binaries/", ""},
                                          {"binaries/x86_64-linux/", ""},
                                          {"resources/mesh/frog.veg", "vertices 4"},
                                          {"documentation/index.html", "<html/>"}}));
  std::filesystem::path directory;
  {
    const FmuArchive archive(fmu);
    directory = archive.directory();
    EXPECT_TRUE(directory.is_absolute());
    EXPECT_EQ(directory.parent_path(), m_extract_root);
    EXPECT_EQ(archive.fmu_path(), fmu);
    EXPECT_EQ(test::read_file(archive.model_description_path()), "<fmiModelDescription/>");
    EXPECT_EQ(test::read_file(archive.resources_directory() / "mesh" / "frog.veg"), "vertices 4");
    EXPECT_EQ(test::read_file(directory / "documentation" / "index.html"), "<html/>");
    EXPECT_TRUE(std::filesystem::is_directory(directory / "binaries" / "x86_64-linux"));
    EXPECT_EQ(archive.resource_path(), (directory / "resources").string() + "/");
    EXPECT_EQ(archive.binary_path("Tissue"), directory / "binaries" / "x86_64-linux" / "Tissue.so");
  }
  EXPECT_FALSE(std::filesystem::exists(directory));
  EXPECT_EQ(leftovers(), 0U);
}

TEST_F(FmuArchiveTest, MovingTransfersOwnershipOfTheDirectory) {
  const std::filesystem::path fmu = m_files.path() / "Valid.fmu";
  ASSERT_NO_FATAL_FAILURE(write_zip(fmu, {{"modelDescription.xml", "x"}}));
  FmuArchive first(fmu);
  const std::filesystem::path directory = first.directory();
  FmuArchive second(std::move(first));
  EXPECT_EQ(second.directory(), directory);
  EXPECT_TRUE(first.directory().empty());  // NOLINT(bugprone-use-after-move): checks the moved-from state
  EXPECT_TRUE(std::filesystem::exists(directory));

  FmuArchive third(fmu);
  const std::filesystem::path replaced = third.directory();
  third = std::move(second);  // the directory third owned is removed
  EXPECT_FALSE(std::filesystem::exists(replaced));
  EXPECT_EQ(third.directory(), directory);
  EXPECT_TRUE(std::filesystem::exists(directory));
}

TEST_F(FmuArchiveTest, ReadsAnArchivePackedByCmakeTar) {
  // The FMU is packed with `cmake -E tar --format=zip`; libzip's strict consistency check
  // (ZIP_CHECKCONS) rejects such archives, so this guards the way FmuArchive opens them.
  const FmuArchive archive(TISSUE_HOST_CMAKE_PACKED_FMU);
  EXPECT_EQ(test::read_file(archive.model_description_path()),
            test::read_file(TISSUE_TISSUE_XML));
  EXPECT_EQ(test::read_file(archive.resources_directory() / "README.md"),
            test::read_file(TISSUE_SOURCE_DIR "/libports/README.md"));
  EXPECT_TRUE(std::filesystem::is_directory(archive.directory() / "binaries" / "x86_64-linux"));
}

TEST_F(FmuArchiveTest, RefusesAMissingFile) { expect_refused(m_files.path() / "absent.fmu", "does not exist"); }

TEST_F(FmuArchiveTest, RefusesAFileThatIsNotAZip) {
  const std::filesystem::path fmu = m_files.path() / "text.fmu";
  test::write_file(fmu, "this is not a zip archive, although it is called .fmu\n");
  expect_refused(fmu, "not a zip archive");
}

TEST_F(FmuArchiveTest, RefusesAZipWithoutModelDescription) {
  const std::filesystem::path fmu = m_files.path() / "NoDescription.fmu";
  ASSERT_NO_FATAL_FAILURE(write_zip(fmu, {{"resources/data.txt", "1"}, {"sub/modelDescription.xml", "x"}}));
  expect_refused(fmu, "no modelDescription.xml");
}

TEST_F(FmuArchiveTest, RefusesZipSlipEntries) {
  for (const std::string name : {"../evil.txt", "resources/../../evil.txt", "/tmp/evil.txt", "..\\evil.txt"}) {
    SCOPED_TRACE(name);
    const std::filesystem::path fmu = m_files.path() / "ZipSlip.fmu";
    ASSERT_NO_FATAL_FAILURE(write_zip(fmu, {{"modelDescription.xml", "x"}, {name, "pwned"}}));
    expect_refused(fmu, "unsafe entry '" + name + "'");
    EXPECT_FALSE(std::filesystem::exists(m_extract_root / "evil.txt"));
    EXPECT_FALSE(std::filesystem::exists(m_files.path() / "evil.txt"));
  }
}

}  // namespace
}  // namespace tissue::host
