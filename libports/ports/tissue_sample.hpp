// The tissue sample: what the Tissue FMU outputs after a step and the HapticLoop FMU takes as its
// tissue.* inputs (the contact's intermediate representation, docs/DESIGN.md, "Haptic loop"), written once.
// Each field is one Tissue output and one HapticLoop input: both FMUs' variable tables make their
// entries from this list (fmu_src/<fmu>/variables.cpp), and the host forwards the sample field by
// field by these names (host/links/sample_relay.hpp). A field added here appears in both
// modelDescription.xml files, both tables and the host's relay. Header only, plain C++20.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace tissue::ports {

/// The element type of a sample field (all are continuous Float64 or discrete Boolean).
enum class SampleType { float64, boolean };

struct SampleField {
  std::string_view tissue_output;  ///< the Tissue FMU's output
  std::string_view haptic_input;   ///< the HapticLoop FMU's input it feeds
  std::uint32_t tissue_vr;
  std::uint32_t haptic_vr;
  SampleType type;
  std::uint64_t rows = 1, columns = 1;  ///< 1 x 1: a scalar; n x 1: a vector [n]; 3 x 3: a matrix [3][3]
  std::string_view unit;                ///< "" for none
  std::string_view haptic_start;        ///< the input's start value (an output has none)
  std::string_view haptic_min;          ///< the input's lower bound ("" for none)
  std::string_view tissue_description;
  std::string_view haptic_description;

  [[nodiscard]] constexpr std::uint64_t size() const { return rows * columns; }
  [[nodiscard]] constexpr int rank() const { return columns > 1 ? 2 : (rows > 1 ? 1 : 0); }
};

/// The haptic loop's tissue.time input: stamped by whoever forwards the sample with the tissue time
/// the sample is for (the communication point the Tissue FMU reached), not one of the Tissue's outputs.
inline constexpr std::string_view SAMPLE_TIME_INPUT = "tissue.time";

inline constexpr auto TISSUE_SAMPLE = std::to_array<SampleField>({
    {"contact.active", "tissue.contactActive", 40, 24, SampleType::boolean, 1, 1, "", "false", "",
     "The probe is in contact with the tissue", "The tissue's contact.active"},
    {"contact.near", "tissue.contactNear", 69, 32, SampleType::boolean, 1, 1, "", "false", "",
     "The probe is not in contact but within contact.nearMargin of the surface: contact.point, contact.normal and "
     "contact.stiffness describe the nearest surface point, so that a haptic loop renders the surface from the "
     "tick the tool crosses it",
     "The tissue's contact.near: render the plane through tissue.contactPoint with normal tissue.contactNormal "
     "and stiffness n^T K_c n from the tick the tool crosses it"},
    {"contact.point", "tissue.contactPoint", 41, 25, SampleType::float64, 3, 1, "m", "0 0 0", "",
     "Contact point on the deformed surface (the god-object position) while contact.active; the nearest surface "
     "point while contact.near; in tool.position's terms: a ball probe's centre where its pole touches",
     "The tissue's contact.point (god-object on the deformed surface)"},
    {"contact.normal", "tissue.contactNormal", 42, 26, SampleType::float64, 3, 1, "1", "0 0 1", "",
     "Unit outward surface normal at contact.point; meaningful while contact.active or contact.near",
     "The tissue's contact.normal (unit outward normal)"},
    {"contact.force", "tissue.contactForce", 43, 27, SampleType::float64, 3, 1, "N", "0 0 0", "",
     "Force of the tissue on the tool",
     "The tissue's contact.force: f0, the force on the tool at tissue.toolPosition"},
    {"contact.stiffness", "tissue.contactStiffness", 44, 28, SampleType::float64, 3, 3, "N/m", "0 0 0 0 0 0 0 0 0", "",
     "Contact stiffness K_c (row-major 3x3) for rendering f = f0 + K_c (x - x0) between tissue updates (while "
     "contact.near: the elementLocal model at contact.point)",
     "The tissue's contact.stiffness K_c (row-major 3x3): the force on the tool is rendered as f0 - K_c (x - x0) "
     "against the contact plane"},
    {"contact.damping", "tissue.contactDamping", 46, 33, SampleType::float64, 3, 3, "N.s/m", "0 0 0 0 0 0 0 0 0", "",
     "Contact damping D_c (row-major 3x3): the tissue's viscous resistance to the tool's motion at the contact, "
     "damping.beta times contact.stiffness (the Rayleigh stiffness-proportional part), so that a haptic loop "
     "renders f = f0 - K_c (x - x0) - D_c (v - v0) between tissue updates (v0: the tool's velocity over the step)",
     "The tissue's contact.damping D_c (row-major 3x3): the part of f0 that is viscous is rendered at the hand's "
     "velocity now, -D_c (v - v0), not held at the velocity of a step ago"},
    {"tool.appliedPosition", "tissue.toolPosition", 67, 29, SampleType::float64, 3, 1, "m", "0 0 0", "",
     "The tool position the last step applied, in tool.position's terms: tool.position, unless the hand's top "
     "speed (tool.maxSpeed) held the tool back on its way there",
     "x0: the tool position the tissue computed its outputs for (the Tissue FMU's tool.appliedPosition)"},
    {"cut.bladeDepth", "tissue.bladeDepth", 65, 30, SampleType::float64, 1, 1, "m", "0", "0",
     "Length of the scalpel's cutting edge inside the tissue while it cuts (0 otherwise): the haptic loop's "
     "cutting force is proportional to it",
     "The tissue's cut.bladeDepth: length of the scalpel's edge inside the tissue"},
});

/// The field whose Tissue output is `tissue_output`; in a constant expression, a name not in the list
/// does not compile.
constexpr const SampleField& sample_field(std::string_view tissue_output) {
  for (const SampleField& field : TISSUE_SAMPLE) {
    if (field.tissue_output == tissue_output) return field;
  }
  throw "no such field in TISSUE_SAMPLE";  // NOLINT(hicpp-exception-baseclass): a compile-time error
}

}  // namespace tissue::ports
