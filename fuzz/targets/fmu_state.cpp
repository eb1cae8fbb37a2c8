// Door: a saved Tissue FMU state handed back to the FMU (fmi3DeserializeFMUState, then
// fmi3SetFMUState and fmi3DoStep), through the FMU's own C ABI. Structure-aware
// (support/state_mutator). Promise: refused with fmi3Error and a logged message, the instance still
// usable; or accepted, restored, and stepping on with finite outputs. After every input the
// instance goes back to the fixture's state (which must always work).
#include "support/promise.hpp"
#include "support/state_mutator.hpp"
#include "support/tissue_fmu_fixture.hpp"

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  return tissue::fuzz::mutate_state(data, size, max_size, seed);
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using tissue::fuzz::broken;
  static tissue::fuzz::TissueFmuFixture fmu;
  fmu.clear_message();
  fmi3FMUState state = nullptr;
  if (fmi3DeserializeFMUState(fmu.instance(), data, size, &state) != fmi3OK) {
    tissue::fuzz::require_message(fmu.message(), "fmi3DeserializeFMUState");
  } else if (fmi3SetFMUState(fmu.instance(), state) != fmi3OK) {
    tissue::fuzz::require_message(fmu.message(), "fmi3SetFMUState");
  } else {
    for (int n = 0; n < 3; ++n) {
      if (fmu.step(0.06, 0.01, 0.019, 1) != fmi3OK) broken("a restored state did not step on:", fmu.message());
      if (!fmu.outputs_finite()) broken("a restored state stepped to non-finite outputs");
    }
  }
  fmi3FreeFMUState(fmu.instance(), &state);
  if (fmi3SetFMUState(fmu.instance(), fmu.baseline()) != fmi3OK)
    broken("the fixture's own state no longer restores:", fmu.message());
  return 0;
}
