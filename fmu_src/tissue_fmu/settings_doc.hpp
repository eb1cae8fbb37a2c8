// The docs' tables of the tissue's settings, generated from the settings schema and the Tissue FMU's
// description: docs/FMU_VARIABLES.md's parameter table and docs/PYTHON.md's keyword table. The tool
// tissue-settings-doc writes them into the docs, and a test checks that the docs hold them.
#pragma once

#include <string>
#include <string_view>

namespace tissue::tissue_fmu {

/// The Tissue FMU's parameters (the settings, then its own), as a Markdown table.
std::string fmu_parameter_table();
/// The Python constructor's keywords (its own, then the settings'), as a Markdown table.
std::string python_keyword_table();

/// `text` with the lines between "<!-- generated: NAME -->" and "<!-- end generated: NAME -->"
/// replaced by `content`. Throws std::invalid_argument when the markers are missing.
std::string with_generated_section(const std::string& text, std::string_view name, const std::string& content);

}  // namespace tissue::tissue_fmu
