// fmu3.hpp - an imported FMI 3.0 Co-Simulation FMU: archive, model description and binary.
//
// Fmu3 is what an importer holds per .fmu file; Fmu3Instance (fmu3_instance.hpp) is one
// running co-simulation instance of it. Several instances of one Fmu3 may coexist (unless the
// FMU says canBeInstantiatedOnlyOncePerProcess).
#pragma once

#include "importer/fmu3_library.hpp"
#include "importer/fmu_archive.hpp"
#include "importer/model_description.hpp"

#include <atomic>
#include <filesystem>
#include <string>

namespace tissue::host {

/**
 * An FMU file opened for co-simulation: unpacked (FmuArchive), its modelDescription.xml parsed
 * and checked (ModelDescription), and binaries/x86_64-linux/<modelIdentifier>.so loaded with all
 * FMI 3.0 functions resolved (Fmu3Library). The constructor also checks that fmi3GetVersion()
 * returns a "3." version. Every refusal is an FmuError naming the .fmu file.
 *
 * Neither copyable nor movable: instances keep a pointer to it, so it must outlive them.
 * Members are destroyed in reverse order: the library is closed before the directory goes.
 */
class Fmu3 {
 public:
  explicit Fmu3(const std::filesystem::path& fmu_path);
  ~Fmu3() = default;

  Fmu3(const Fmu3&) = delete;
  Fmu3& operator=(const Fmu3&) = delete;
  Fmu3(Fmu3&&) = delete;
  Fmu3& operator=(Fmu3&&) = delete;

  [[nodiscard]] const FmuArchive& archive() const { return m_archive; }
  [[nodiscard]] const ModelDescription& description() const { return m_description; }
  [[nodiscard]] const Fmu3Library& library() const { return m_library; }
  [[nodiscard]] const Fmu3Functions& functions() const { return m_library.functions(); }
  /// What the binary's fmi3GetVersion() returned.
  [[nodiscard]] const std::string& version() const { return m_version; }
  /// Number of live Fmu3Instance objects of this FMU.
  [[nodiscard]] int instance_count() const { return m_instance_count.load(); }

 private:
  friend class Fmu3Instance;

  FmuArchive m_archive;
  ModelDescription m_description;
  Fmu3Library m_library;
  std::string m_version;
  mutable std::atomic<int> m_instance_count{0};
};

}  // namespace tissue::host
