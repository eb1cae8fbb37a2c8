// Where the tests find the read-only Vega reference meshes (../shared/meshes/vega beside the
// checkout). A checkout without ../shared skips the tests that compare against them, saying why.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>

namespace tissue::test_data {

inline std::filesystem::path vega_reference_dir() {
  return std::filesystem::path(TISSUE_SHARED_DIR) / "meshes" / "vega";
}

}  // namespace tissue::test_data

/// Skips the current test when the reference meshes are not beside the checkout.
#define TISSUE_SKIP_WITHOUT_VEGA_MESHES()                                                       \
  if (!std::filesystem::is_directory(::tissue::test_data::vega_reference_dir()))                \
  GTEST_SKIP() << "reference meshes not found at " << ::tissue::test_data::vega_reference_dir() \
               << " (../shared is not beside this checkout)"
