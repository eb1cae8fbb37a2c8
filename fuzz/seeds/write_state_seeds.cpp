// Writes the state door's seeds (fuzz/corpus/fmu_state/): the fixture's states at rest, after the
// stroke, and pressed by the probe. `fuzz_state_seeds <folder>`.
#include "support/tissue_fmu_fixture.hpp"

#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <folder>\n", argv[0]);
    return 2;
  }
  tissue::fuzz::TissueFmuFixture fmu;
  const auto write = [&](const std::string& name) {
    const std::vector<std::uint8_t> bytes = fmu.serialized_state();
    std::ofstream(std::string(argv[1]) + "/" + name, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  };
  write("after_stroke");
  for (int n = 0; n < 5; ++n) fmu.step(0.03, 0.01, 0.019 - 0.001 * n, 1);  // the probe pressed in
  write("probe_pressed");
  for (int n = 0; n < 5; ++n) fmu.step(0.08, 0.01, 0.01, 2);  // the scalpel into the free end
  write("second_cut");
  return 0;
}
