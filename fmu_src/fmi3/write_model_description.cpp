// The build's writer of one FMU's modelDescription.xml from its port schema (compiled once per FMU
// by tissue_add_fmu: TISSUE_FMU_VARIABLES_HEADER declares TISSUE_FMU_DESCRIPTION()).
// Usage: <fmu>_model_description OUTPUT.xml. Rewrites OUTPUT only when its text changes.
#include TISSUE_FMU_VARIABLES_HEADER

#include "fmi3/model_description_xml.hpp"

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
    const std::string xml = tissue::fmi3::model_description_xml(TISSUE_FMU_DESCRIPTION());
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
    std::cerr << "modelDescription: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
