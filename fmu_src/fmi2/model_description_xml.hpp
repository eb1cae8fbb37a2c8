// The FMI 2.0 Co-Simulation modelDescription.xml of an FMU, written from the same port schema as
// its FMI 3.0 one, through the ScalarLayout (scalar_layout.hpp): indexed scalars with dense value
// references, enumerations as SimpleTypes, the ModelStructure by index. Plain C++, no FMI headers.
#pragma once

#include "fmi2/scalar_layout.hpp"

#include <string>

namespace tissue::fmi2 {

/// Throws fmi3::SchemaError naming what it cannot write.
std::string model_description_xml(const ScalarLayout& layout);

}  // namespace tissue::fmi2
