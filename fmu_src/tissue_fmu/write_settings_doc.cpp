// tissue-settings-doc DOCS_DIR [--check]: writes the settings' tables (settings_doc.hpp) into
// DOCS_DIR/FMU_VARIABLES.md and DOCS_DIR/PYTHON.md, or with --check says which doc differs and exits 1.
#include "tissue_fmu/settings_doc.hpp"

#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace {

std::string read(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tissue::tissue_fmu;
  if (argc < 2 || argc > 3 || (argc == 3 && std::string(argv[2]) != "--check")) {
    std::cerr << "usage: tissue-settings-doc DOCS_DIR [--check]\n";
    return 2;
  }
  const std::filesystem::path docs(argv[1]);
  const bool check = argc == 3;
  int stale = 0;
  try {
    const std::pair<const char*, std::string> sections[] = {{"FMU_VARIABLES.md", fmu_parameter_table()},
                                                            {"PYTHON.md", python_keyword_table()}};
    for (const auto& [file, table] : sections) {
      const std::filesystem::path path = docs / file;
      const std::string text = read(path);
      const std::string updated = with_generated_section(text, "settings", table);
      if (updated == text) continue;
      if (check) {
        std::cerr << path.string() << ": the settings table differs from the schema's (run tissue-settings-doc "
                  << docs.string() << ")\n";
        ++stale;
      } else {
        std::ofstream(path, std::ios::binary) << updated;
        std::cout << "wrote " << path.string() << "\n";
      }
    }
  } catch (const std::exception& error) {
    std::cerr << "tissue-settings-doc: " << error.what() << "\n";
    return 1;
  }
  return stale == 0 ? 0 : 1;
}
