// Every range an FMU declares in its modelDescription (min/max of its parameters) is the range its
// model enforces: for each scalar Float64, Int32 and UInt64 parameter with a bound, through the
// importer on the packaged FMU, the start value and each bound (FMI bounds are inclusive) are
// accepted, and the nearest value beyond a bound is refused with fmi3Error. The declarative table
// and the core's validate() cannot drift apart unnoticed. Built once per FMU (TISSUE_FMU_PATH).
#include "importer/fmu3.hpp"
#include "importer/fmu3_instance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace tissue::host {
namespace {

const Fmu3& fmu() {
  static const Fmu3 loaded(TISSUE_FMU_PATH);
  return loaded;
}

// Sets `text` (a number as written in the XML, moved by `nudge` steps beyond it) on a fresh instance.
fmi3Status set_scalar(const ModelVariable& variable, const std::string& text, int nudge) {
  Fmu3Instance instance(fmu(), "ranges", false);
  if (variable.type == "Float64") {
    const double value = std::stod(text);
    const double step = std::max(1e-12, std::abs(value) * 1e-9);
    return instance.set_float64(variable.name, {value + nudge * step});
  }
  if (variable.type == "Int32") {
    return instance.set_int32(variable.name, {static_cast<std::int32_t>(std::stol(text) + nudge)});
  }
  const long long value = std::stoll(text) + nudge;
  if (value < 0) return fmi3Error;  // below an unsigned type's range: nothing to try
  return instance.set_uint64(variable.name, {static_cast<std::uint64_t>(value)});
}

TEST(DeclaredRanges, AreTheRangesTheModelEnforces) {
  int checked = 0;
  for (const ModelVariable& variable : fmu().description().variables()) {
    const bool parameter = variable.causality == "parameter" || variable.causality == "structuralParameter";
    const bool numeric = variable.type == "Float64" || variable.type == "Int32" || variable.type == "UInt64";
    if (!parameter || !numeric || variable.is_array() || !variable.start) continue;
    EXPECT_EQ(set_scalar(variable, *variable.start, 0), fmi3OK) << variable.name << ": the start value";
    if (variable.min) {
      EXPECT_EQ(set_scalar(variable, *variable.min, 0), fmi3OK) << variable.name << " = min " << *variable.min;
      if (!(variable.type == "UInt64" && std::stoll(*variable.min) == 0)) {
        EXPECT_EQ(set_scalar(variable, *variable.min, -1), fmi3Error) << variable.name << " just below min";
      }
      ++checked;
    }
    if (variable.max) {
      EXPECT_EQ(set_scalar(variable, *variable.max, 0), fmi3OK) << variable.name << " = max " << *variable.max;
      EXPECT_EQ(set_scalar(variable, *variable.max, +1), fmi3Error) << variable.name << " just above max";
      ++checked;
    }
  }
  EXPECT_GT(checked, 0) << "no declared range was found to check";
}

}  // namespace
}  // namespace tissue::host
