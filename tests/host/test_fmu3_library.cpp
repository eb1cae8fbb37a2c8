// test_fmu3_library.cpp - Fmu3Library and Fmu3 refusing binaries that are missing or incomplete,
// and the FMI 3.0 function list shared with the FMU.
#include "fmi3_function_names.hpp"
#include "host_test_support.hpp"
#include "importer/fmu3.hpp"
#include "importer/fmu3_library.hpp"
#include "importer/fmu_error.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>

extern "C" int tissue_host_abi_function_type_count(void);

namespace tissue::host {
namespace {

using test::TempDir;
using test::write_zip;

/// Runs @p action, expecting an FmuError; returns its message ("" and a failure if none).
template <typename Action>
std::string refusal_of(Action action) {
  try {
    action();
  } catch (const FmuError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an FmuError";
  return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(Fmi3FunctionNames, ListsEveryFmi3FunctionOnce) {
  const std::set<std::string_view> unique(fmi3::FMI3_FUNCTION_NAMES.begin(), fmi3::FMI3_FUNCTION_NAMES.end());
  EXPECT_EQ(unique.size(), fmi3::FMI3_FUNCTION_NAMES.size());
  for (const std::string_view name : fmi3::FMI3_FUNCTION_NAMES) {
    EXPECT_EQ(name.substr(0, 4), "fmi3") << name;
  }
  EXPECT_TRUE(unique.contains("fmi3InstantiateCoSimulation"));
  EXPECT_TRUE(unique.contains("fmi3ActivateModelPartition"));
  // abi_compiles.c (compiled as C) declares one pointer per function type of fmi3_abi.h.
  EXPECT_EQ(static_cast<std::size_t>(tissue_host_abi_function_type_count()), fmi3::FMI3_FUNCTION_NAMES.size());
}

TEST(Fmu3Library, RefusesAMissingBinary) {
  const std::string message = refusal_of([] { const Fmu3Library library("/nonexistent/binaries/Model.so"); });
  EXPECT_TRUE(contains(message, "/nonexistent/binaries/Model.so")) << message;
  EXPECT_TRUE(contains(message, "does not exist")) << message;
}

TEST(Fmu3Library, RefusesAFileThatIsNotASharedLibrary) {
  const TempDir dir;
  test::write_file(dir.path() / "Model.so", "not an ELF file");
  const std::string message = refusal_of([&] { const Fmu3Library library(dir.path() / "Model.so"); });
  EXPECT_TRUE(contains(message, "cannot load FMU binary")) << message;
}

TEST(Fmu3Library, RefusesABinaryLackingFunctionsAndListsThemAll) {
  const std::string message = refusal_of([] { const Fmu3Library library(TISSUE_PARTIAL_FMI3_BINARY); });
  EXPECT_TRUE(contains(message, "does not export 73 of the 75 FMI 3.0 functions")) << message;
  for (const std::string_view name : fmi3::FMI3_FUNCTION_NAMES) {
    const bool exported = name == "fmi3GetVersion" || name == "fmi3DoStep";
    // Match "name," or "name" at the end, so that fmi3GetFloat32 does not match fmi3GetFloat32x.
    const bool listed = contains(message + ",", std::string(name) + ",");
    EXPECT_EQ(listed, !exported) << name;
  }
}

TEST(Fmu3, RefusesAnFmuWithoutBinaryForThisPlatform) {
  const TempDir dir;
  const std::filesystem::path fmu = dir.path() / "NoBinary.fmu";
  ASSERT_NO_FATAL_FAILURE(write_zip(
      fmu, {{"modelDescription.xml", test::model_description_xml()}, {"binaries/x86_64-windows/Minimal.dll", "MZ"}}));
  const std::string message = refusal_of([&] { const Fmu3 imported(fmu); });
  EXPECT_TRUE(contains(message, fmu.string())) << message;
  EXPECT_TRUE(contains(message, "binaries/x86_64-linux/Minimal.so")) << message;
}

TEST(Fmu3, RefusesTheTissueDescriptionPackedWithoutBinary) {
  const std::string message = refusal_of([] { const Fmu3 imported(TISSUE_HOST_CMAKE_PACKED_FMU); });
  EXPECT_TRUE(contains(message, "binaries/x86_64-linux/Tissue.so")) << message;
}

TEST(Fmu3, RefusesAnFmuWhoseBinaryLacksFunctions) {
  const TempDir dir;
  const std::filesystem::path fmu = dir.path() / "Partial.fmu";
  ASSERT_NO_FATAL_FAILURE(
      write_zip(fmu, {{"modelDescription.xml", test::model_description_xml()},
                      {"binaries/x86_64-linux/Minimal.so", test::read_file(TISSUE_PARTIAL_FMI3_BINARY)}}));
  const std::string message = refusal_of([&] { const Fmu3 imported(fmu); });
  EXPECT_TRUE(contains(message, fmu.string())) << message;
  EXPECT_TRUE(contains(message, "fmi3InstantiateCoSimulation")) << message;
}

TEST(Fmu3, RefusesAnFmuWithAnInvalidModelDescription) {
  const TempDir dir;
  const std::filesystem::path fmu = dir.path() / "Fmi2.fmu";
  ASSERT_NO_FATAL_FAILURE(
      write_zip(fmu, {{"modelDescription.xml",
                       test::model_description_xml("", "", R"(<CoSimulation modelIdentifier="Minimal"/>)", "2.0")}}));
  const std::string message = refusal_of([&] { const Fmu3 imported(fmu); });
  EXPECT_TRUE(contains(message, fmu.string())) << message;
  EXPECT_TRUE(contains(message, "fmiVersion '2.0'")) << message;
}

}  // namespace
}  // namespace tissue::host
