// The SSP (System Structure and Parameterization 1.0) of the pair: Tissue and HapticLoop as FMI 2.0
// components wired as tissue-host wires them, for co-simulation masters that read SSP (FMPy's
// simulate_ssp, OMSimulator). The connections are made from the same port lists as the FMUs:
// every field of the tissue sample (ports/tissue_sample.hpp) element by element, the tissue time
// (sample.time -> tissue.time), and the tool (HapticLoop tool.position and tool.mode -> Tissue).
// The system's inputs are the hand: device.position[1..3] and device.toolMode (the instrument in
// hand, so that a master that starts every connector at 0, as FMPy does, starts with no tool rather
// than with a probe at the origin); its outputs the force to render on the hand,
// device.force[1..3]. Plain C++, no SSP library.
#pragma once

#include "fmi2/scalar_layout.hpp"

#include <string>
#include <vector>

namespace tissue::ssp {

struct Connection {
  std::string start_element;  ///< "" for a system connector
  std::string start_connector;
  std::string end_element;  ///< "" for a system connector
  std::string end_connector;
};

/// The connections, each checked against the two layouts (the start an output, the end an input,
/// of the same 2.0 type; every name a scalar). Throws fmi3::SchemaError naming the connector.
std::vector<Connection> connections(const fmi2::ScalarLayout& tissue, const fmi2::ScalarLayout& haptic);

/// SystemStructure.ssd referencing resources/Tissue.fmu, resources/HapticLoop.fmu and the
/// parameter set resources/TissueHaptic.ssv.
std::string system_structure_ssd(const fmi2::ScalarLayout& tissue, const fmi2::ScalarLayout& haptic);
/// TissueHaptic.ssv: both FMUs stepped at the haptic rate (stepSize 1 ms).
std::string parameter_values_ssv();

}  // namespace tissue::ssp
