// fmu3.cpp - opening an FMU file: unpack, parse, load, check the version.
#include "importer/fmu3.hpp"

#include "importer/fmu_error.hpp"

#include <string_view>

namespace tissue::host {
namespace {

ModelDescription load_description(const FmuArchive& archive) {
  try {
    return load_model_description(archive.model_description_path());
  } catch (const FmuError& error) {
    throw FmuError("FMU '" + archive.fmu_path().string() + "': " + error.what());
  }
}

Fmu3Library load_library(const FmuArchive& archive, const ModelDescription& description) {
  try {
    return Fmu3Library(archive.binary_path(description.co_simulation().model_identifier));
  } catch (const FmuError& error) {
    throw FmuError("FMU '" + archive.fmu_path().string() + "': " + error.what());
  }
}

}  // namespace

Fmu3::Fmu3(const std::filesystem::path& fmu_path)
    : m_archive(fmu_path),
      m_description(load_description(m_archive)),
      m_library(load_library(m_archive, m_description)) {
  const char* version = m_library.functions().fmi3GetVersion();
  m_version = version == nullptr ? std::string() : std::string(version);
  if (m_version.rfind("3.", 0) != 0) {
    throw FmuError("FMU '" + fmu_path.string() + "': fmi3GetVersion() returned '" + m_version +
                   "', expected an FMI 3.x version such as \"" fmi3Version "\"");
  }
}

}  // namespace tissue::host
