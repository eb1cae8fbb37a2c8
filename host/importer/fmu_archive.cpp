// fmu_archive.cpp - extraction of an .fmu (zip) with libzip into a private temporary directory.
#include "importer/fmu_archive.hpp"

#include "importer/fmu_error.hpp"

#include <zip.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

namespace tissue::host {
namespace {

/// Closes a read-only libzip archive without writing anything back.
struct ZipDiscard {
  void operator()(zip_t* archive) const noexcept { zip_discard(archive); }
};
using ZipHandle = std::unique_ptr<zip_t, ZipDiscard>;

/// Closes a file inside a libzip archive.
struct ZipFileClose {
  void operator()(zip_file_t* file) const noexcept { zip_fclose(file); }
};
using ZipFileHandle = std::unique_ptr<zip_file_t, ZipFileClose>;

std::string quoted(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

/// libzip's text for an error code returned by zip_open.
std::string zip_error_text(int code) {
  zip_error_t error;
  zip_error_init_with_code(&error, code);
  std::string text = zip_error_strerror(&error);
  zip_error_fini(&error);
  return text;
}

/**
 * True if an entry name is a safe relative path: not empty, not absolute (POSIX or
 * Windows-style, including a drive letter), and without a ".." component. Backslashes are
 * treated as separators too, so "..\\x" is caught whichever tool wrote the archive.
 */
bool is_safe_entry_name(std::string_view name) {
  if (name.empty() || name.front() == '/' || name.front() == '\\') {
    return false;
  }
  if (name.find(':') != std::string_view::npos) {
    return false;  // "C:/..." or an NTFS stream; never a valid FMU path
  }
  std::size_t begin = 0;
  while (begin <= name.size()) {
    const std::size_t end = name.find_first_of("/\\", begin);
    const std::string_view part = name.substr(begin, end == std::string_view::npos ? end : end - begin);
    if (part == "..") {
      return false;
    }
    if (end == std::string_view::npos) {
      break;
    }
    begin = end + 1;
  }
  return true;
}

/// Makes a fresh directory "tissue-fmu-XXXXXX" under the system temporary directory.
std::filesystem::path make_temporary_directory(const std::filesystem::path& fmu_path) {
  std::error_code error;
  const std::filesystem::path base = std::filesystem::temp_directory_path(error);
  if (error) {
    throw FmuError("cannot extract FMU " + quoted(fmu_path) + ": no temporary directory (" + error.message() + ")");
  }
  std::string pattern = (base / "tissue-fmu-XXXXXX").string();
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (mkdtemp(buffer.data()) == nullptr) {
    throw FmuError("cannot extract FMU " + quoted(fmu_path) + ": mkdtemp in " + quoted(base) + " failed (" +
                   std::strerror(errno) + ")");
  }
  return std::filesystem::absolute(std::filesystem::path(buffer.data()));
}

/// Writes entry @p index of @p archive to @p target.
void extract_file(zip_t* archive, zip_uint64_t index, const std::string& name, const std::filesystem::path& target,
                  const std::filesystem::path& fmu_path) {
  ZipFileHandle file(zip_fopen_index(archive, index, 0));
  if (!file) {
    throw FmuError("cannot read entry '" + name + "' of FMU " + quoted(fmu_path) + ": " + zip_strerror(archive));
  }
  std::ofstream out(target, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw FmuError("cannot write " + quoted(target) + " while extracting FMU " + quoted(fmu_path));
  }
  std::vector<char> buffer(1 << 16);
  for (;;) {
    const zip_int64_t count = zip_fread(file.get(), buffer.data(), buffer.size());
    if (count < 0) {
      throw FmuError("cannot read entry '" + name + "' of FMU " + quoted(fmu_path) + ": " +
                     zip_file_strerror(file.get()));
    }
    if (count == 0) {
      break;
    }
    out.write(buffer.data(), static_cast<std::streamsize>(count));
  }
  if (!out.flush()) {
    throw FmuError("cannot write " + quoted(target) + " while extracting FMU " + quoted(fmu_path));
  }
}

/// Extracts every entry of the zip at @p fmu_path into @p directory, after checking all names.
void extract_all(const std::filesystem::path& fmu_path, const std::filesystem::path& directory) {
  // No ZIP_CHECKCONS: archives written by `cmake -E tar --format=zip` (how the FMU is packed,
  // as in Reference-FMUs) fail libzip's strict consistency check although they are readable.
  int open_error = 0;
  ZipHandle archive(zip_open(fmu_path.c_str(), ZIP_RDONLY, &open_error));
  if (!archive) {
    if (open_error == ZIP_ER_NOZIP || open_error == ZIP_ER_INCONS) {
      throw FmuError("FMU " + quoted(fmu_path) + " is not a zip archive (" + zip_error_text(open_error) + ")");
    }
    throw FmuError("cannot open FMU " + quoted(fmu_path) + ": " + zip_error_text(open_error));
  }

  const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(count > 0 ? count : 0));
  bool has_model_description = false;
  for (zip_int64_t i = 0; i < count; ++i) {
    const char* raw = zip_get_name(archive.get(), static_cast<zip_uint64_t>(i), ZIP_FL_ENC_GUESS);
    if (raw == nullptr) {
      throw FmuError("cannot read entry " + std::to_string(i) + " of FMU " + quoted(fmu_path) + ": " +
                     zip_strerror(archive.get()));
    }
    std::string name = raw;
    if (!is_safe_entry_name(name)) {
      throw FmuError("FMU " + quoted(fmu_path) + " contains the unsafe entry '" + name +
                     "' (absolute path or '..'); refusing to extract it");
    }
    has_model_description = has_model_description || name == "modelDescription.xml";
    names.push_back(std::move(name));
  }
  if (!has_model_description) {
    throw FmuError("FMU " + quoted(fmu_path) + " has no modelDescription.xml at the root of the archive");
  }

  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& name = names[i];
    const std::filesystem::path target = directory / std::filesystem::path(name).relative_path();
    std::error_code error;
    if (name.back() == '/' || name.back() == '\\') {
      std::filesystem::create_directories(target, error);
    } else {
      std::filesystem::create_directories(target.parent_path(), error);
    }
    if (error) {
      throw FmuError("cannot create " + quoted(target) + " while extracting FMU " + quoted(fmu_path) + ": " +
                     error.message());
    }
    if (name.back() != '/' && name.back() != '\\') {
      extract_file(archive.get(), static_cast<zip_uint64_t>(i), name, target, fmu_path);
    }
  }
}

}  // namespace

FmuArchive::FmuArchive(const std::filesystem::path& fmu_path) : m_fmu_path(fmu_path) {
  std::error_code error;
  if (!std::filesystem::exists(fmu_path, error)) {
    throw FmuError("FMU file " + quoted(fmu_path) + " does not exist");
  }
  if (!std::filesystem::is_regular_file(fmu_path, error)) {
    throw FmuError("FMU " + quoted(fmu_path) + " is not a regular file");
  }
  m_directory = make_temporary_directory(fmu_path);
  try {
    extract_all(fmu_path, m_directory);
  } catch (...) {
    remove_directory();  // the destructor does not run when the constructor throws
    throw;
  }
}

FmuArchive::~FmuArchive() { remove_directory(); }

FmuArchive::FmuArchive(FmuArchive&& other) noexcept
    : m_fmu_path(std::move(other.m_fmu_path)), m_directory(std::exchange(other.m_directory, {})) {}

FmuArchive& FmuArchive::operator=(FmuArchive&& other) noexcept {
  if (this != &other) {
    remove_directory();
    m_fmu_path = std::move(other.m_fmu_path);
    m_directory = std::exchange(other.m_directory, {});
  }
  return *this;
}

std::filesystem::path FmuArchive::model_description_path() const { return m_directory / "modelDescription.xml"; }

std::filesystem::path FmuArchive::resources_directory() const { return m_directory / "resources"; }

std::string FmuArchive::resource_path() const { return resources_directory().string() + "/"; }

std::filesystem::path FmuArchive::binary_path(std::string_view model_identifier) const {
  return m_directory / "binaries" / std::string(FMI3_PLATFORM) / (std::string(model_identifier) + ".so");
}

void FmuArchive::remove_directory() noexcept {
  if (!m_directory.empty()) {
    std::error_code ignored;  // nothing sensible to do about a failure in a destructor
    std::filesystem::remove_all(m_directory, ignored);
    m_directory.clear();
  }
}

std::string read_text_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw FmuError("cannot open " + quoted(path));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    throw FmuError("cannot read " + quoted(path));
  }
  return text.str();
}

}  // namespace tissue::host
