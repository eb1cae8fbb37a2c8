// A TOML table of FMU parameters by name ([tissue.parameters], a compare setting's parameters)
// read into ParameterSettings, with the scenario's rules: numbers, integers, booleans, strings
// (enumeration items) and arrays of numbers; anything else refused naming `origin` and `where`.
#pragma once

#include "scenario/scenario.hpp"

#define TOML_EXCEPTIONS 1
#include <toml++/toml.h>

#include <string>
#include <vector>

namespace tissue::host {

/// The table's entries in file order; throws ScenarioError ("origin: where.key: why").
std::vector<ParameterSetting> read_parameter_table(const toml::table& table, const std::string& where,
                                                   const std::string& origin);

}  // namespace tissue::host
