// The build's writer of one FMU's FMI 2.0 modelDescription.xml from its port schema (compiled once
// per FMU by tissue_add_fmu, as fmi3/write_model_description.cpp is for 3.0).
// Usage: <fmu>_fmi2_model_description OUTPUT.xml. Rewrites OUTPUT only when its text changes.
#include TISSUE_FMU_VARIABLES_HEADER

#include "fmi2/model_description_xml.hpp"

#include <exception>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " OUTPUT.xml\n";
    return 2;
  }
  try {
    const tissue::fmi2::ScalarLayout layout(TISSUE_FMU_DESCRIPTION());
    const std::string xml = tissue::fmi2::model_description_xml(layout);
    std::ifstream existing(argv[1], std::ios::binary);
    if (existing && std::string(std::istreambuf_iterator<char>(existing), {}) == xml) return 0;
    existing.close();
    std::ofstream out(argv[1], std::ios::binary | std::ios::trunc);
    out << xml;
    if (!out) {
      std::cerr << argv[1] << ": cannot be written\n";
      return 1;
    }
  } catch (const std::exception& error) {
    std::cerr << "modelDescription (FMI 2.0): " << error.what() << "\n";
    return 1;
  }
  return 0;
}
