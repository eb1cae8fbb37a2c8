// The build's writer of the pair's SSP files (system_structure.hpp).
// Usage: tissue-write-ssp SystemStructure.ssd TissueHaptic.ssv
#include "fmi2/scalar_layout.hpp"
#include "haptic_loop/variables.hpp"
#include "ssp/system_structure.hpp"
#include "tissue_fmu/variables.hpp"

#include <exception>
#include <fstream>
#include <iostream>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: " << argv[0] << " SystemStructure.ssd TissueHaptic.ssv\n";
    return 2;
  }
  try {
    const tissue::fmi2::ScalarLayout tissue(tissue::tissue_fmu::tissue_model_description());
    const tissue::fmi2::ScalarLayout haptic(tissue::haptic_fmu::haptic_loop_model_description());
    std::ofstream(argv[1], std::ios::binary | std::ios::trunc) << tissue::ssp::system_structure_ssd(tissue, haptic);
    std::ofstream(argv[2], std::ios::binary | std::ios::trunc) << tissue::ssp::parameter_values_ssv();
  } catch (const std::exception& error) {
    std::cerr << "SSP: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
