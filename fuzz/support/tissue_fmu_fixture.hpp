// The Tissue FMU as an importer sees it, linked into the fuzz target (its C ABI, fmi3_functions.cpp,
// over the FMU's model): one instance on a 200-tet beam, initialized, with a scalpel stroke drawn
// across it so that its states carry cuts. Used by the state door and by the seed writer.
#pragma once

#include "fmi3_abi.h"

#include <cstdint>
#include <string>
#include <vector>

namespace tissue::fuzz {

class TissueFmuFixture {
 public:
  TissueFmuFixture();
  ~TissueFmuFixture();
  TissueFmuFixture(const TissueFmuFixture&) = delete;
  TissueFmuFixture& operator=(const TissueFmuFixture&) = delete;

  [[nodiscard]] fmi3Instance instance() const { return m_instance; }
  /// Steps with the scalpel at `position_m` (mode 2) or the probe (mode 1).
  fmi3Status step(double x_m, double y_m, double z_m, std::int64_t mode);
  /// The messages the FMU logged since clear_message(), joined by " | ".
  [[nodiscard]] const std::string& message() const { return m_message; }
  void clear_message() { m_message.clear(); }
  /// The serialized state of the instance now.
  [[nodiscard]] std::vector<std::uint8_t> serialized_state();
  /// The state after the stroke (restored after every input).
  [[nodiscard]] fmi3FMUState baseline() const { return m_baseline; }
  /// contact.force finite.
  [[nodiscard]] bool outputs_finite();

 private:
  static void log(fmi3InstanceEnvironment environment, fmi3Status, fmi3String, fmi3String message);
  fmi3Instance m_instance = nullptr;
  fmi3FMUState m_baseline = nullptr;
  std::string m_message;
};

}  // namespace tissue::fuzz
