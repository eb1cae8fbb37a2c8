// The port schema is the one source of the variables: the tissue sample's fields
// (ports/tissue_sample.hpp) make both FMUs' table entries, the written modelDescription.xml files and
// the host's relay. A field added to the sample list alone appears in the Tissue's outputs and the
// HapticLoop's inputs, in both XMLs (read back by the host's own parser) and in the relay's layout;
// a field one FMU lacks is refused by the host naming it. (A Vr enumerator naming a field that is
// not in the list does not compile: ports::sample_field is evaluated at compile time there.)
#include "fmi3/model_description_xml.hpp"
#include "haptic_loop/variables.hpp"
#include "importer/fmu_error.hpp"
#include "importer/model_description.hpp"
#include "links/sample_relay.hpp"
#include "ports/surface_binary.hpp"
#include "tissue_fmu/variables.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <array>
#include <string>

namespace tissue {
namespace {

using host::ModelDescription;
using host::ModelVariable;
using host::parse_model_description;

// The sample with one made-up field more: the work the tissue did on the tool.
constexpr auto EXTENDED_SAMPLE = [] {
  std::array<ports::SampleField, ports::TISSUE_SAMPLE.size() + 1> fields{};
  std::copy(ports::TISSUE_SAMPLE.begin(), ports::TISSUE_SAMPLE.end(), fields.begin());
  fields.back() = {"contact.work", "tissue.contactWork", 68, 31, ports::SampleType::float64, 1, 1, "J", "0", "",
                   "Work the tissue did on the tool", "The tissue's contact.work"};
  return fields;
}();

constexpr auto EXTENDED_TISSUE = tissue_fmu::tissue_variables(EXTENDED_SAMPLE);
constexpr auto EXTENDED_HAPTIC = haptic_fmu::haptic_loop_variables(EXTENDED_SAMPLE);
static_assert(fmi3::strictly_ordered(EXTENDED_TISSUE) && fmi3::strictly_ordered(EXTENDED_HAPTIC));

ModelDescription written_and_read(const fmi3::ModelDescription& description) {
  return parse_model_description(fmi3::model_description_xml(description));
}

// The Binary surface outputs round-trip, and bytes that are not their layout are refused with the
// output's name: truncated, trailing bytes, another output's magic, an index out of range, a NaN.
TEST(SurfaceBinary, RoundTripsAndRefusesWhatIsNotItsLayout) {
  ports::SurfaceMesh mesh{{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 1, 2}, 1};
  std::vector<std::uint8_t> bytes;
  ports::encode(mesh, bytes);
  EXPECT_EQ(bytes.size(), 32u + 9 * 8 + 3 * 4);
  ports::SurfaceMesh back;
  ports::decode(bytes, back);
  EXPECT_EQ(back.positions_m, mesh.positions_m);
  EXPECT_EQ(back.triangles, mesh.triangles);
  EXPECT_EQ(back.cut_triangle_count, 1u);
  const auto refused = [](std::vector<std::uint8_t> b, const std::string& why) {
    ports::SurfaceMesh m;
    try {
      ports::decode(b, m);
      ADD_FAILURE() << "accepted: " << why;
    } catch (const ports::SurfaceBinaryError& error) {
      EXPECT_NE(std::string(error.what()).find("surface.mesh: " + why), std::string::npos) << error.what();
    }
  };
  refused({bytes.begin(), bytes.end() - 1}, "truncated");
  std::vector<std::uint8_t> longer = bytes;
  longer.push_back(0);
  refused(longer, "trailing bytes");
  std::vector<std::uint8_t> other = bytes;
  other[3] = 'X';
  refused(other, "not this output");
  ports::SurfaceMesh bad_index = mesh;
  bad_index.triangles[2] = 3;
  ports::encode(bad_index, bytes);
  refused(bytes, "a triangle names row 3 of 3");
  ports::SurfaceMesh nan = mesh;
  nan.positions_m[4] = std::nan("");
  ports::encode(nan, bytes);
  refused(bytes, "a non-finite position");

  ports::SurfaceEmbedding embedding;
  embedding.revision = 7;
  embedding.node_count = 2;
  embedding.point_nodes = {0, 1, 1, 1, 1, 0, 0, 0, 0, 1, 0, 0};
  embedding.point_weights = {0.5, 0.5, 0, 0, 1, 0, 0, 0, 0.25, 0.75, 0, 0};
  embedding.triangles = {0, 1, 2};
  ports::encode(embedding, bytes);
  ports::SurfaceEmbedding embedding_back;
  ports::decode(bytes, embedding_back);
  EXPECT_EQ(embedding_back.point_nodes, embedding.point_nodes);
  EXPECT_EQ(embedding_back.revision, 7u);
  std::vector<double> mapped;
  ports::map_points(embedding_back, ports::SurfaceNodes{7, {0, 0, 0, 4, 0, 0}}, mapped);
  EXPECT_EQ(mapped, (std::vector<double>{2, 0, 0, 4, 0, 0, 3, 0, 0}));
  EXPECT_THROW(ports::map_points(embedding_back, ports::SurfaceNodes{6, {0, 0, 0, 4, 0, 0}}, mapped),
               ports::SurfaceBinaryError);
  embedding.point_nodes[5] = 2;
  ports::encode(embedding, bytes);
  EXPECT_THROW(ports::decode(bytes, embedding_back), ports::SurfaceBinaryError);
}

TEST(PortSchema, EverySampleFieldIsATissueOutputAndAHapticInputInTheWrittenXml) {
  const ModelDescription tissue = written_and_read(tissue_fmu::tissue_model_description());
  const ModelDescription haptic = written_and_read(haptic_fmu::haptic_loop_model_description());
  for (const ports::SampleField& field : ports::TISSUE_SAMPLE) {
    const ModelVariable* out = tissue.find_variable(field.tissue_output);
    const ModelVariable* in = haptic.find_variable(field.haptic_input);
    ASSERT_NE(out, nullptr) << field.tissue_output;
    ASSERT_NE(in, nullptr) << field.haptic_input;
    EXPECT_EQ(out->causality, "output") << field.tissue_output;
    EXPECT_EQ(in->causality, "input") << field.haptic_input;
    EXPECT_EQ(out->value_reference, field.tissue_vr) << field.tissue_output;
    EXPECT_EQ(in->value_reference, field.haptic_vr) << field.haptic_input;
    EXPECT_EQ(tissue.array_size(*out), field.size()) << field.tissue_output;
    EXPECT_EQ(haptic.array_size(*in), field.size()) << field.haptic_input;
    EXPECT_EQ(out->unit, field.unit) << field.tissue_output;
  }
  const host::SampleLayout layout(ports::TISSUE_SAMPLE, tissue, haptic);
  EXPECT_EQ(layout.number_count(), 3U + 3U + 3U + 9U + 9U + 3U + 1U);  // point, normal, force, K_c, D_c, x0, blade depth
  EXPECT_EQ(layout.flag_count(), 2U);                             // contact.active, contact.near
}

TEST(PortSchema, AFieldAddedToTheSampleAloneAppearsInBothXmlsAndTheHostsRelay) {
  const ModelDescription tissue = written_and_read(tissue_fmu::tissue_model_description(EXTENDED_TISSUE));
  const ModelDescription haptic = written_and_read(haptic_fmu::haptic_loop_model_description(EXTENDED_HAPTIC));
  const ModelVariable* out = tissue.find_variable("contact.work");
  const ModelVariable* in = haptic.find_variable("tissue.contactWork");
  ASSERT_NE(out, nullptr);
  ASSERT_NE(in, nullptr);
  EXPECT_EQ(out->causality, "output");
  EXPECT_EQ(out->unit, "J");
  EXPECT_EQ(in->causality, "input");
  EXPECT_EQ(in->start.value_or(""), "0");
  // One variable more than the real Tissue FMU, nothing else changed.
  EXPECT_EQ(tissue.variables().size(), tissue_fmu::tissue_model_description().variables.size() + 1);

  const host::SampleLayout real(ports::TISSUE_SAMPLE, tissue, haptic);
  const host::SampleLayout layout(EXTENDED_SAMPLE, tissue, haptic);
  const host::SampleSlot slot = layout.slot("contact.work");
  EXPECT_EQ(slot.size, 1U);
  EXPECT_EQ(layout.number_count(), real.number_count() + 1);
  EXPECT_EQ(slot.offset, real.number_count());  // after the others: nothing else moved
  EXPECT_NE(std::find(layout.tissue_numbers().begin(), layout.tissue_numbers().end(), 68U),
            layout.tissue_numbers().end());
  EXPECT_NE(std::find(layout.haptic_numbers().begin(), layout.haptic_numbers().end(), 31U),
            layout.haptic_numbers().end());
}

TEST(PortSchema, AFieldOneFmuLacksIsRefusedNamingIt) {
  const ModelDescription tissue = written_and_read(tissue_fmu::tissue_model_description(EXTENDED_TISSUE));
  const ModelDescription haptic = written_and_read(haptic_fmu::haptic_loop_model_description());  // without it
  try {
    const host::SampleLayout layout(EXTENDED_SAMPLE, tissue, haptic);
    FAIL() << "a HapticLoop without tissue.contactWork was accepted";
  } catch (const host::FmuError& error) {
    EXPECT_NE(std::string(error.what()).find("tissue.contactWork"), std::string::npos) << error.what();
  }
}

TEST(PortSchema, AUnitWithoutSiDefinitionFailsTheWriterNamingTheVariable) {
  auto variables = tissue_fmu::tissue_variables(ports::TISSUE_SAMPLE);
  for (fmi3::VariableInfo& info : variables) {
    if (info.name == "contact.depth") info.unit = "furlong";
  }
  try {
    (void)fmi3::model_description_xml(tissue_fmu::tissue_model_description(variables));
    FAIL() << "a unit with no SI definition was written";
  } catch (const fmi3::SchemaError& error) {
    EXPECT_NE(std::string(error.what()).find("contact.depth"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace tissue
