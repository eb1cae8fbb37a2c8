// test_model_description.cpp - parse_model_description: what it reads and what it refuses.
#include "host_test_support.hpp"
#include "importer/fmu_error.hpp"
#include "importer/model_description.hpp"

#include <gtest/gtest.h>

#include <string>

namespace tissue::host {
namespace {

using test::model_description_xml;

/// Expects parse_model_description(@p xml) to throw an FmuError whose message contains @p part.
void expect_refused(const std::string& xml, const std::string& part) {
  try {
    (void)parse_model_description(xml);
    ADD_FAILURE() << "accepted, expected a refusal mentioning '" << part << "'";
  } catch (const FmuError& error) {
    EXPECT_NE(std::string(error.what()).find(part), std::string::npos)
        << "message '" << error.what() << "' does not mention '" << part << "'";
  }
}

TEST(ModelDescription, ReadsAMinimalCoSimulationDescription) {
  const ModelDescription md = parse_model_description(model_description_xml(
      R"(<Float64 name="x" valueReference="1" causality="output" initial="calculated" unit="m" description="position"/>
           <Int32 name="n" valueReference="2" causality="parameter" variability="fixed" start="7" min="1" max="9"/>
           <Boolean name="flag" valueReference="3"/>)",
      "", R"(<CoSimulation modelIdentifier="Minimal" canGetAndSetFMUState="true" needsExecutionTool="false"/>)"));

  EXPECT_EQ(md.fmi_version(), "3.0");
  EXPECT_EQ(md.model_name(), "Minimal");
  EXPECT_EQ(md.instantiation_token(), "{8c4e810f-3df3-4a00-8276-176fa3c9f000}");
  EXPECT_EQ(md.co_simulation().model_identifier, "Minimal");
  EXPECT_TRUE(md.co_simulation().can_get_and_set_fmu_state);
  EXPECT_FALSE(md.co_simulation().can_serialize_fmu_state);  // default false
  EXPECT_FALSE(md.co_simulation().can_handle_variable_communication_step_size);
  EXPECT_FALSE(md.default_experiment().has_value());
  ASSERT_EQ(md.variables().size(), 4U);
  EXPECT_EQ(md.independent_variable().name, "time");

  const ModelVariable& x = md.variable("x");
  EXPECT_EQ(x.type, "Float64");
  EXPECT_EQ(x.value_reference, 1U);
  EXPECT_EQ(x.causality, "output");
  EXPECT_EQ(x.variability, "continuous");  // default for Float64
  EXPECT_EQ(x.initial, "calculated");
  EXPECT_EQ(x.unit, "m");
  EXPECT_EQ(x.description, "position");
  EXPECT_FALSE(x.start.has_value());
  EXPECT_FALSE(x.is_array());
  EXPECT_EQ(md.array_size(x), 1U);

  const ModelVariable& n = md.variable(2U);
  EXPECT_EQ(n.name, "n");
  EXPECT_EQ(n.start, "7");
  EXPECT_EQ(n.min, "1");
  EXPECT_EQ(n.max, "9");

  const ModelVariable& flag = md.variable("flag");
  EXPECT_EQ(flag.causality, "local");       // default causality
  EXPECT_EQ(flag.variability, "discrete");  // default for non-float types

  EXPECT_EQ(md.find_variable("nope"), nullptr);
  EXPECT_EQ(md.find_variable(99U), nullptr);
  EXPECT_THROW((void)md.variable("nope"), FmuError);
  EXPECT_THROW((void)md.variable(99U), FmuError);
}

TEST(ModelDescription, ReadsExperimentLogCategoriesUnitsAndCapabilities) {
  const ModelDescription md = parse_model_description(model_description_xml(
      R"(<Float64 name="f" valueReference="1" causality="output" declaredType="Force"/>)",
      R"(<UnitDefinitions><Unit name="N"><BaseUnit kg="1" m="1" s="-2"/></Unit><Unit name="m"/></UnitDefinitions>
           <TypeDefinitions><Float64Type name="Force" unit="N"/></TypeDefinitions>
           <LogCategories><Category name="logEvents" description="Events"/><Category name="logCalls"/></LogCategories>
           <DefaultExperiment startTime="0" stopTime="2.5" stepSize="0.01"/>)",
      R"(<CoSimulation modelIdentifier="M" canSerializeFMUState="true" canGetAndSetFMUState="true"
               canHandleVariableCommunicationStepSize="true" fixedInternalStepSize="0.001" maxOutputDerivativeOrder="2"/>)"));

  const CoSimulationCapabilities& caps = md.co_simulation();
  EXPECT_EQ(caps.model_identifier, "M");
  EXPECT_TRUE(caps.can_serialize_fmu_state);
  EXPECT_TRUE(caps.can_handle_variable_communication_step_size);
  EXPECT_EQ(caps.fixed_internal_step_size_s, 0.001);
  EXPECT_EQ(caps.max_output_derivative_order, 2U);

  ASSERT_TRUE(md.default_experiment().has_value());
  EXPECT_EQ(md.default_experiment()->start_time_s, 0.0);
  EXPECT_EQ(md.default_experiment()->stop_time_s, 2.5);
  EXPECT_EQ(md.default_experiment()->step_size_s, 0.01);
  EXPECT_FALSE(md.default_experiment()->tolerance.has_value());

  ASSERT_EQ(md.log_categories().size(), 2U);
  EXPECT_EQ(md.log_categories()[0].name, "logEvents");
  EXPECT_EQ(md.log_categories()[0].description, "Events");
  EXPECT_EQ(md.log_categories()[1].name, "logCalls");
  EXPECT_EQ(md.unit_names(), (std::vector<std::string>{"N", "m"}));
  // The unit comes from the declared type when the variable has none.
  EXPECT_EQ(md.variable("f").declared_type, "Force");
  EXPECT_EQ(md.variable("f").unit, "N");
}

TEST(ModelDescription, SizesArraysFromFixedAndStructuralDimensions) {
  const ModelDescription md = parse_model_description(model_description_xml(
      R"(<UInt64 name="rows" valueReference="10" causality="structuralParameter" variability="fixed" start="4"/>
           <Float64 name="matrix" valueReference="11" causality="output" initial="calculated" start="1 2 3">
             <Dimension valueReference="10"/>
             <Dimension start="3"/>
           </Float64>
           <Float64 name="g" valueReference="12" causality="parameter" variability="fixed" start="0 0 -9.81">
             <Dimension start="3"/>
           </Float64>)"));

  const ModelVariable& matrix = md.variable("matrix");
  ASSERT_TRUE(matrix.is_array());
  ASSERT_EQ(matrix.dimensions.size(), 2U);
  EXPECT_EQ(matrix.dimensions[0].value_reference, 10U);
  EXPECT_FALSE(matrix.dimensions[0].start.has_value());
  EXPECT_EQ(matrix.dimensions[1].start, 3U);
  EXPECT_EQ(md.array_size(matrix), 12U);                  // 4 rows (start) x 3
  EXPECT_EQ(md.array_size(matrix, {{10U, 100U}}), 300U);  // rows set to 100
  EXPECT_EQ(md.array_size(matrix, {{10U, 0U}}), 0U);      // an empty array is allowed
  EXPECT_EQ(md.array_size(md.variable("g")), 3U);
  EXPECT_EQ(md.variable("g").start, "0 0 -9.81");
}

TEST(ModelDescription, ReadsEnumerationsAndStringStarts) {
  const ModelDescription md = parse_model_description(model_description_xml(
      R"(<Enumeration name="mode" valueReference="1" causality="input" declaredType="Mode" start="2"/>
           <String name="mesh" valueReference="2" causality="parameter" variability="fixed"><Start value="frog"/></String>)",
      R"(<TypeDefinitions>
             <EnumerationType name="Mode" description="tool mode">
               <Item name="none" value="0"/>
               <Item name="probe" value="1" description="pushes"/>
               <Item name="scalpel" value="2"/>
             </EnumerationType>
           </TypeDefinitions>)"));

  const TypeDefinition* mode_type = md.find_type("Mode");
  ASSERT_NE(mode_type, nullptr);
  EXPECT_EQ(mode_type->kind, "EnumerationType");
  EXPECT_EQ(mode_type->description, "tool mode");
  ASSERT_EQ(mode_type->items.size(), 3U);
  EXPECT_EQ(mode_type->items[1].name, "probe");
  EXPECT_EQ(mode_type->items[1].value, 1);
  EXPECT_EQ(mode_type->items[1].description, "pushes");
  EXPECT_EQ(mode_type->items[2].value, 2);

  const ModelVariable& mode = md.variable("mode");
  EXPECT_EQ(mode.type, "Enumeration");
  EXPECT_EQ(mode.declared_type, "Mode");
  EXPECT_EQ(mode.variability, "discrete");
  EXPECT_EQ(mode.start, "2");
  EXPECT_EQ(md.variable("mesh").start, "frog");  // from <Start value=""/>
  EXPECT_EQ(md.find_type("Nope"), nullptr);
}

TEST(ModelDescription, ReadsTheTissueFmuDescription) {
  const ModelDescription md = load_model_description(TISSUE_TISSUE_XML);
  EXPECT_EQ(md.model_name(), "Tissue");
  EXPECT_EQ(md.co_simulation().model_identifier, "Tissue");
  EXPECT_TRUE(md.co_simulation().can_get_and_set_fmu_state);
  EXPECT_TRUE(md.co_simulation().can_serialize_fmu_state);
  EXPECT_EQ(md.independent_variable().name, "time");

  const ModelVariable& positions = md.variable("surface.vertexPositions");
  const ModelVariable& capacity = md.variable("surface.vertexCapacity");
  ASSERT_TRUE(capacity.start.has_value());
  const std::size_t rows = std::stoull(*capacity.start);
  EXPECT_EQ(md.array_size(positions), rows * 3);
  EXPECT_EQ(md.array_size(positions, {{capacity.value_reference, 10U}}), 30U);
  EXPECT_EQ(md.array_size(md.variable("contact.stiffness")), 9U);
  EXPECT_EQ(md.variable("contact.force").unit, "N");
  EXPECT_EQ(md.variable("tool.mode").type, "Enumeration");
  ASSERT_NE(md.find_type(md.variable("tool.mode").declared_type), nullptr);
}

TEST(ModelDescription, RefusesOtherFmiVersions) {
  expect_refused(model_description_xml("", "", R"(<CoSimulation modelIdentifier="M"/>)", "2.0"), "'2.0'");
  expect_refused(model_description_xml("", "", R"(<CoSimulation modelIdentifier="M"/>)", ""), "fmiVersion");
}

TEST(ModelDescription, RefusesDuplicateValueReferencesAndNames) {
  expect_refused(model_description_xml(R"(<Float64 name="a" valueReference="1"/><Int32 name="b" valueReference="1"/>)"),
                 "'a' and 'b' have the same valueReference 1");
  expect_refused(model_description_xml(R"(<Float64 name="a" valueReference="1"/><Int32 name="a" valueReference="2"/>)"),
                 "variable name 'a' is used twice");
}

TEST(ModelDescription, RefusesBadDimensionReferences) {
  expect_refused(
      model_description_xml(R"(<Float64 name="v" valueReference="1"><Dimension valueReference="42"/></Float64>)"),
      "refers to valueReference 42, which is not a variable");
  expect_refused(
      model_description_xml(R"(<UInt64 name="n" valueReference="2" causality="parameter" variability="fixed" start="3"/>
                                 <Float64 name="v" valueReference="1"><Dimension valueReference="2"/></Float64>)"),
      "which is not a structural parameter");
  expect_refused(
      model_description_xml(
          R"(<Int32 name="n" valueReference="2" causality="structuralParameter" variability="fixed" start="3"/>
                                 <Float64 name="v" valueReference="1"><Dimension valueReference="2"/></Float64>)"),
      "not <UInt64>");
  expect_refused(model_description_xml(R"(<Float64 name="v" valueReference="1"><Dimension/></Float64>)"),
                 "exactly one of start and valueReference");
}

TEST(ModelDescription, RefusesADescriptionWithoutCoSimulation) {
  expect_refused(model_description_xml("", "", R"(<ModelExchange modelIdentifier="M"/>)"), "no <CoSimulation>");
  expect_refused(model_description_xml("", "", R"(<CoSimulation/>)"), "no modelIdentifier");
}

TEST(ModelDescription, RefusesMissingOrInvalidAttributes) {
  // No independent variable: replace the one the helper writes.
  std::string xml = model_description_xml();
  const std::string time = R"(causality="independent")";
  xml.replace(xml.find(time), time.size(), R"(causality="local")");
  expect_refused(xml, "no variable with causality 'independent'");

  expect_refused(model_description_xml(R"(<Float64 name="t2" valueReference="1" causality="independent"/>)"),
                 "more than one independent variable");
  expect_refused(model_description_xml(R"(<Float64 name="a" valueReference="1" causality="sideways"/>)"),
                 "unknown causality 'sideways'");
  expect_refused(model_description_xml(R"(<Float64 name="a" valueReference="1" variability="sometimes"/>)"),
                 "unknown variability 'sometimes'");
  expect_refused(model_description_xml(R"(<Int32 name="a" valueReference="1" variability="continuous"/>)"),
                 "only Float32/Float64 may be continuous");
  expect_refused(model_description_xml(R"(<Float64 name="a"/>)"), "'a' has no valueReference");
  expect_refused(model_description_xml(R"(<Float64 name="a" valueReference="-1"/>)"), "not a valid integer");
  expect_refused(model_description_xml(R"(<Float64 valueReference="1"/>)"), "has no name");
  expect_refused(model_description_xml(R"(<Real name="a" valueReference="1"/>)"), "unknown element <Real>");
  expect_refused(model_description_xml(R"(<Float64 name="a" valueReference="1" declaredType="Missing"/>)"),
                 "declaredType 'Missing'");
  expect_refused(model_description_xml(R"(<Enumeration name="a" valueReference="1"/>)"),
                 "without an EnumerationType declaredType");
  expect_refused(R"(<fmiModelDescription fmiVersion="3.0" modelName="M">)", "not well-formed XML");
  expect_refused(
      R"(<fmiModelDescription fmiVersion="3.0" modelName="M"><CoSimulation modelIdentifier="M"/></fmiModelDescription>)",
      "no instantiationToken");
}

}  // namespace
}  // namespace tissue::host
