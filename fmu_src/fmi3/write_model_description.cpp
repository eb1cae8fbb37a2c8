// The build's writer of one FMU's modelDescription.xml from its port schema (compiled once per FMU
// by tissue_add_fmu: TISSUE_FMU_VARIABLES_HEADER declares TISSUE_FMU_DESCRIPTION()).
// Usage: <fmu>_model_description OUTPUT.xml. Rewrites OUTPUT only when its text changes.
#include TISSUE_FMU_VARIABLES_HEADER

#include "fmi3/model_description_xml.hpp"

int main(int argc, char** argv) {
  return tissue::fmi3::write_description_main(argc, argv, "modelDescription", [] {
    return tissue::fmi3::model_description_xml(TISSUE_FMU_DESCRIPTION());
  });
}
