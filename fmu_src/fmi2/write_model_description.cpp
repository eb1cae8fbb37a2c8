// The build's writer of one FMU's FMI 2.0 modelDescription.xml from its port schema (compiled once
// per FMU by tissue_add_fmu, as fmi3/write_model_description.cpp is for 3.0).
// Usage: <fmu>_fmi2_model_description OUTPUT.xml. Rewrites OUTPUT only when its text changes.
#include TISSUE_FMU_VARIABLES_HEADER

#include "fmi2/model_description_xml.hpp"
#include "fmi3/model_description_xml.hpp"

int main(int argc, char** argv) {
  return tissue::fmi3::write_description_main(argc, argv, "modelDescription (FMI 2.0)", [] {
    return tissue::fmi2::model_description_xml(tissue::fmi2::ScalarLayout(TISSUE_FMU_DESCRIPTION()));
  });
}
