// An FMU's modelDescription XML against the FMI 3.0 schema (xmllint) and against its variable table
// in code (fmu_src/<fmu>/variables.cpp): the XML is the contract importers read, the table is what the
// FMI layer drives everything from (starts, ranges, sizes, which calls may set what), and this test
// keeps them one: every start value, range, unit, shape, description and enumeration item. A
// difference names the variable and the attribute. Also checks what the schema cannot: the
// standard's defaults, ModelStructure, units. Built once per FMU (tests/fmu/model_description.cmake):
// TISSUE_FMU_VARIABLES_HEADER declares TISSUE_FMU_DESCRIPTION(), the FMU's fmi3::ModelDescription.
#include TISSUE_FMU_VARIABLES_HEADER

#include <gtest/gtest.h>
#include <pugixml.hpp>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace tissue::fmi3 {
namespace {

const ModelDescription& description() { return TISSUE_FMU_DESCRIPTION(); }
std::span<const VariableInfo> variables() { return description().variables; }
const VariableInfo* find_variable(std::uint32_t vr) { return description().find(vr); }
const VariableInfo* find_variable(std::string_view name) { return description().find(name); }

constexpr const char* XML_PATH = TISSUE_MODEL_DESCRIPTION_XML;
constexpr const char* SCHEMA_DIR = TISSUE_FMI3_SCHEMA_DIR;

// Parsed once for all tests; a file that does not parse fails every test that reads it.
struct LoadedModelDescription {
  pugi::xml_document document;
  pugi::xml_parse_result result = document.load_file(XML_PATH);
};

const pugi::xml_document& model_description() {
  static const LoadedModelDescription loaded;
  if (!loaded.result) {
    ADD_FAILURE() << "cannot parse " << XML_PATH << ": " << loaded.result.description() << " at offset "
                  << loaded.result.offset;
  }
  return loaded.document;
}

pugi::xml_node root() { return model_description().child("fmiModelDescription"); }

std::optional<std::filesystem::path> find_on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream directories(path != nullptr ? path : "");
  for (std::string directory; std::getline(directories, directory, ':');) {
    const std::filesystem::path candidate = std::filesystem::path(directory) / program;
    if (!directory.empty() && std::filesystem::exists(candidate)) return candidate;
  }
  return std::nullopt;
}

// xs:list values may be separated by any whitespace; compare them in one spelling.
std::string collapse_whitespace(std::string_view text) {
  std::string result;
  bool pending_space = false;
  for (const char c : text) {
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
      pending_space = !result.empty();
    } else {
      if (pending_space) result += ' ';
      pending_space = false;
      result += c;
    }
  }
  return result;
}

// FMI 3.0.1, "variability": fixed for (structural, calculated) parameters; otherwise continuous for
// Float32/Float64 and discrete for the other types.
std::string default_variability(std::string_view element, std::string_view causality) {
  if (causality == "parameter" || causality == "structuralParameter" || causality == "calculatedParameter") {
    return "fixed";
  }
  return element == "Float32" || element == "Float64" ? "continuous" : "discrete";
}

// FMI 3.0, "initial" (the table over causality and variability): the initial a variable has when
// the attribute is absent; "" where initial is not allowed (inputs, the independent variable).
std::string default_initial(std::string_view causality, std::string_view variability) {
  if (variability == "constant") return "exact";
  if (causality == "parameter" || causality == "structuralParameter") return "exact";
  if (causality == "calculatedParameter" || causality == "output" || causality == "local") return "calculated";
  return "";
}

// Everything the comparison looks at, as text, resolved the same way from either side.
struct Resolved {
  std::string element, name, causality, variability, unit, declared_type, start, min, max, shape, description;
};

constexpr std::array<std::pair<std::string_view, std::string Resolved::*>, 11> COMPARED = {{
    {"name", &Resolved::name},
    {"element type", &Resolved::element},
    {"causality", &Resolved::causality},
    {"variability", &Resolved::variability},
    {"unit", &Resolved::unit},
    {"declaredType", &Resolved::declared_type},
    {"start", &Resolved::start},
    {"min", &Resolved::min},
    {"max", &Resolved::max},
    {"dimensions", &Resolved::shape},
    {"description", &Resolved::description},
}};

std::string format_dimension(std::uint64_t size, std::optional<std::uint64_t> size_vr) {
  std::string text = size_vr ? "[vr " : "[";
  text.append(std::to_string(size_vr ? *size_vr : size)).append("]");
  return text;
}

Resolved from_code(const VariableInfo& info) {
  Resolved r;
  r.element = to_string(info.type);
  r.name = info.name;
  r.causality = to_string(info.causality);
  r.variability = to_string(info.variability);
  r.unit = info.unit;
  r.declared_type = info.declared_type;
  r.start = info.start;
  r.min = info.min;
  r.max = info.max;
  for (int i = 0; i < info.rank; ++i) {
    const Dimension& d = info.dimensions.at(static_cast<std::size_t>(i));
    r.shape += format_dimension(
        d.size, d.size_vr >= 0 ? std::optional<std::uint64_t>(static_cast<std::uint64_t>(d.size_vr)) : std::nullopt);
  }
  r.description = info.description;
  return r;
}

// An attribute of the variable, else of its declared type (FMI 3.0: the variable's overrides).
std::string attribute_or_declared(pugi::xml_node variable, const char* attribute) {
  if (const pugi::xml_attribute own = variable.attribute(attribute)) return own.value();
  const char* declared = variable.attribute("declaredType").value();
  if (*declared == '\0') return "";
  const pugi::xml_node type = root().child("TypeDefinitions").find_child_by_attribute("name", declared);
  return type.attribute(attribute).value();
}

Resolved from_xml(pugi::xml_node variable) {
  Resolved r;
  r.element = variable.name();
  r.name = variable.attribute("name").value();
  r.causality = variable.attribute("causality").as_string("local");
  r.variability = variable.attribute("variability").as_string(default_variability(r.element, r.causality).c_str());
  r.unit = attribute_or_declared(variable, "unit");
  r.declared_type = variable.attribute("declaredType").value();
  if (r.element == "String" || r.element == "Binary") {
    for (const pugi::xml_node start : variable.children("Start")) {
      if (!r.start.empty()) r.start += ' ';
      r.start += start.attribute("value").value();
    }
  } else {
    r.start = collapse_whitespace(variable.attribute("start").value());
  }
  r.min = attribute_or_declared(variable, "min");
  r.max = attribute_or_declared(variable, "max");
  for (const pugi::xml_node dimension : variable.children("Dimension")) {
    const pugi::xml_attribute size_vr = dimension.attribute("valueReference");
    r.shape += format_dimension(dimension.attribute("start").as_ullong(),
                                size_vr ? std::optional<std::uint64_t>(size_vr.as_ullong()) : std::nullopt);
  }
  r.description = variable.attribute("description").value();
  return r;
}

// The XML's variables by value reference; a repeated value reference or name is a failure.
std::map<std::uint32_t, pugi::xml_node> xml_variables() {
  std::map<std::uint32_t, pugi::xml_node> by_vr;
  std::set<std::string> names;
  for (const pugi::xml_node variable : root().child("ModelVariables").children()) {
    const std::uint32_t vr = variable.attribute("valueReference").as_uint();
    if (!by_vr.emplace(vr, variable).second) ADD_FAILURE() << "the XML: value reference " << vr << " used twice";
    if (!names.insert(variable.attribute("name").value()).second) {
      ADD_FAILURE() << "the XML: name " << variable.attribute("name").value() << " used twice";
    }
  }
  return by_vr;
}

std::set<std::uint32_t> model_structure(const char* element) {
  std::set<std::uint32_t> vrs;
  for (const pugi::xml_node unknown : root().child("ModelStructure").children(element)) {
    vrs.insert(unknown.attribute("valueReference").as_uint());
  }
  return vrs;
}

TEST(ModelDescription, ValidatesAgainstTheFmi3Schema) {
  const std::filesystem::path schema = std::filesystem::path(SCHEMA_DIR) / "fmi3ModelDescription.xsd";
  if (!std::filesystem::exists(schema)) {
    GTEST_SKIP() << "FMI 3.0 schema not found at " << schema
                 << " (../shared is not beside this checkout); the schema check needs it";
  }
  ASSERT_TRUE(find_on_path("xmllint").has_value())
      << "xmllint is not on PATH: install libxml2-utils to validate " << XML_PATH;
  const std::string command = "xmllint --noout --schema '" + schema.string() + "' '" + XML_PATH + "'";
  EXPECT_EQ(std::system(command.c_str()), 0) << command << " failed: its messages are above";
}

TEST(ModelDescription, IdentifiesTheFmuAsTheCodeDoes) {
  const pugi::xml_node description = root();
  ASSERT_FALSE(description.empty()) << XML_PATH << " has no fmiModelDescription";
  EXPECT_STREQ(description.attribute("fmiVersion").value(), "3.0");
  EXPECT_EQ(std::string_view(description.attribute("modelName").value()), fmi3::description().model_identifier);
  EXPECT_EQ(std::string_view(description.attribute("instantiationToken").value()),
            fmi3::description().instantiation_token)
      << "instantiationToken differs from the code's";
  EXPECT_STREQ(description.attribute("variableNamingConvention").value(), "structured");
  const pugi::xml_node co_simulation = description.child("CoSimulation");
  ASSERT_FALSE(co_simulation.empty()) << "no CoSimulation element";
  EXPECT_EQ(std::string_view(co_simulation.attribute("modelIdentifier").value()), fmi3::description().model_identifier)
      << "modelIdentifier differs from the code's";
  // Rollback is part of the product (docs/DESIGN.md, "FMI layer": FMU states).
  EXPECT_TRUE(co_simulation.attribute("canGetAndSetFMUState").as_bool());
  EXPECT_TRUE(co_simulation.attribute("canSerializeFMUState").as_bool());
  EXPECT_TRUE(description.child("ModelExchange").empty());
}

TEST(ModelDescription, EveryVariableEqualsTheCodeTable) {
  const auto xml = xml_variables();
  std::map<std::uint32_t, const VariableInfo*> code;
  for (const VariableInfo& info : variables()) code.emplace(static_cast<std::uint32_t>(info.vr), &info);
  EXPECT_EQ(xml.size(), variables().size()) << "the XML and variables.cpp have different numbers of variables";

  for (const auto& [vr, node] : xml) {
    if (!code.contains(vr)) {
      ADD_FAILURE() << "vr " << vr << " (" << node.attribute("name").value()
                    << ") is in the XML but not in variables.cpp";
    }
  }
  for (const auto& [vr, info] : code) {
    const auto it = xml.find(vr);
    if (it == xml.end()) {
      ADD_FAILURE() << "vr " << vr << " (" << info->name << ") is in variables.cpp but not in the XML";
      continue;
    }
    const Resolved from_file = from_xml(it->second);
    const Resolved from_table = from_code(*info);
    for (const auto& [attribute, field] : COMPARED) {
      if (from_file.*field != from_table.*field) {
        ADD_FAILURE() << "vr " << vr << " (" << info->name << "): " << attribute << " differs: XML \""
                      << from_file.*field << "\", variables.cpp \"" << from_table.*field << "\"";
      }
    }
  }
}

// "Type.item" (built by appending: GCC 12 warns falsely on operator+ chains here).
std::string item_key(std::string_view type, std::string_view item) {
  std::string key(type);
  key.append(".").append(item);
  return key;
}

TEST(ModelDescription, EnumerationTypesHaveTheDocumentedItems) {
  using Items = std::vector<std::pair<std::string, long long>>;
  std::map<std::string, Items> expected;  // the code's enumeration types (the layer checks values against them)
  std::map<std::string, std::string> descriptions;
  for (const EnumerationType& type : description().enumerations) {
    Items& items = expected[std::string(type.name)];
    for (const EnumerationItem& item : type.items) {
      items.emplace_back(std::string(item.name), item.value);
      descriptions[item_key(type.name, item.name)] = item.description;
    }
  }
  std::map<std::string, Items> actual;
  for (const pugi::xml_node type : root().child("TypeDefinitions").children("EnumerationType")) {
    Items& items = actual[type.attribute("name").value()];
    for (const pugi::xml_node item : type.children("Item")) {
      items.emplace_back(item.attribute("name").value(), item.attribute("value").as_llong());
      const std::string key = item_key(type.attribute("name").value(), item.attribute("name").value());
      EXPECT_FALSE(std::string_view(item.attribute("description").value()).empty()) << key << " has no description";
      EXPECT_EQ(descriptions[key], item.attribute("description").value()) << key << ": description differs";
    }
  }
  EXPECT_EQ(actual, expected);

  for (const VariableInfo& info : variables()) {
    if (info.type != VariableType::enumeration) {
      EXPECT_TRUE(info.declared_type.empty()) << info.name << ": only enumerations have a declared type here";
      continue;
    }
    ASSERT_TRUE(expected.contains(std::string(info.declared_type))) << info.name << ": unknown " << info.declared_type;
    const Items& items = expected.at(std::string(info.declared_type));
    if (info.causality == Causality::output) continue;  // outputs have no start
    const bool start_is_an_item = std::ranges::any_of(
        items, [&](const auto& item) { return std::to_string(item.second) == std::string(info.start); });
    EXPECT_TRUE(start_is_an_item) << info.name << ": start " << info.start << " is not a " << info.declared_type;
  }
}

TEST(ModelDescription, ModelStructureListsEveryOutputAndInitialUnknown) {
  std::set<std::uint32_t> outputs, initial_unknowns;
  for (const auto& [vr, node] : xml_variables()) {
    const Resolved r = from_xml(node);
    const std::string initial =
        node.attribute("initial").as_string(default_initial(r.causality, r.variability).c_str());
    if (r.causality == "output") outputs.insert(vr);
    // FMI 3.0, ModelStructure: outputs and calculated parameters with initial approx or calculated.
    if ((r.causality == "output" || r.causality == "calculatedParameter") &&
        (initial == "calculated" || initial == "approx")) {
      initial_unknowns.insert(vr);
    }
    if (initial == "calculated") {
      EXPECT_TRUE(node.attribute("start").empty() && node.child("Start").empty())
          << r.name << ": initial calculated must not have a start";
    }
  }
  EXPECT_FALSE(outputs.empty());
  EXPECT_EQ(model_structure("Output"), outputs) << "ModelStructure's <Output> elements are not exactly the outputs";
  EXPECT_EQ(model_structure("InitialUnknown"), initial_unknowns)
      << "ModelStructure's <InitialUnknown> elements are not exactly the outputs with initial calculated/approx";
}

TEST(ModelDescription, UnitsAreDefinedWithTheirSiBaseUnits) {
  // Exponents of kg, m, s of every unit either FMU may use; each XML defines the ones it uses.
  const std::map<std::string, std::array<int, 3>> known = {
      {"1", {0, 0, 0}},      {"m", {0, 1, 0}},     {"s", {0, 0, 1}},    {"kg", {1, 0, 0}},   {"N", {1, 1, -2}},
      {"Pa", {1, -1, -2}},   {"J", {1, 2, -2}},    {"N/m", {1, 0, -2}}, {"N/s", {1, 1, -3}}, {"J/m2", {1, 0, -2}},
      {"kg/m3", {1, -3, 0}}, {"m/s2", {0, 1, -2}}, {"m/s", {0, 1, -1}}, {"1/s", {0, 0, -1}}, {"Hz", {0, 0, -1}},
      {"N.s/m", {1, 0, -1}},
  };
  std::map<std::string, std::array<int, 3>> expected;
  for (const pugi::xml_node unit : root().child("UnitDefinitions").children("Unit")) {
    const auto it = known.find(unit.attribute("name").value());
    if (it == known.end()) {
      ADD_FAILURE() << "unit " << unit.attribute("name").value() << " is not one this test knows";
    } else {
      expected.insert(*it);
    }
  }
  std::map<std::string, std::array<int, 3>> defined;
  for (const pugi::xml_node unit : root().child("UnitDefinitions").children("Unit")) {
    const pugi::xml_node base = unit.child("BaseUnit");
    ASSERT_FALSE(base.empty()) << "unit " << unit.attribute("name").value() << " has no BaseUnit";
    for (const char* other : {"A", "K", "mol", "cd", "rad"}) {
      EXPECT_EQ(base.attribute(other).as_int(), 0) << "unit " << unit.attribute("name").value();
    }
    EXPECT_EQ(base.attribute("factor").as_double(1.0), 1.0) << "unit " << unit.attribute("name").value();
    EXPECT_EQ(base.attribute("offset").as_double(0.0), 0.0) << "unit " << unit.attribute("name").value();
    defined[unit.attribute("name").value()] = {base.attribute("kg").as_int(), base.attribute("m").as_int(),
                                               base.attribute("s").as_int()};
  }
  EXPECT_EQ(defined, expected);
  for (const VariableInfo& info : variables()) {
    if (!info.unit.empty()) {
      EXPECT_TRUE(defined.contains(std::string(info.unit))) << info.name << ": unit " << info.unit << " is not defined";
    }
  }
}

TEST(ModelDescription, ListsTheLogCategories) {
  std::vector<std::string> names;
  for (const pugi::xml_node category : root().child("LogCategories").children("Category")) {
    names.emplace_back(category.attribute("name").value());
    EXPECT_FALSE(std::string_view(category.attribute("description").value()).empty())
        << "log category " << names.back() << " has no description";
  }
  const std::vector<std::string> expected = {"logStatusWarning", "logStatusError", "logStatusFatal", "logCalls",
                                             "logEvents"};
  EXPECT_EQ(names, expected);
}

// The table on its own: what find_variable() relies on and what the standard asks of it.
TEST(VariableTable, IsOrderedAndFindableByValueReferenceAndName) {
  std::set<std::string_view> names;
  std::uint32_t previous = 0;
  bool first = true;
  for (const VariableInfo& info : variables()) {
    const auto vr = static_cast<std::uint32_t>(info.vr);
    EXPECT_TRUE(first || vr > previous) << info.name << " is out of value-reference order";
    first = false;
    previous = vr;
    EXPECT_TRUE(names.insert(info.name).second) << info.name << " appears twice";
    EXPECT_EQ(find_variable(vr), &info) << info.name;
    EXPECT_EQ(find_variable(info.name), &info) << info.name;
  }
  std::uint32_t missing = 0;
  while (std::ranges::any_of(variables(), [&](const VariableInfo& info) { return info.vr == missing; })) ++missing;
  EXPECT_EQ(find_variable(missing), nullptr);
  EXPECT_EQ(find_variable(std::uint32_t{100000}), nullptr);
  EXPECT_EQ(find_variable(std::string_view("no.such.variable")), nullptr);
  EXPECT_EQ(find_variable(std::string_view("")), nullptr);
}

TEST(VariableTable, StartsShapesAndDimensionsFollowTheStandard) {
  for (const VariableInfo& info : variables()) {
    SCOPED_TRACE(std::string(info.name));
    const bool computed = info.causality == Causality::output || info.causality == Causality::independent;
    // Outputs are initial calculated (no start); inputs and parameters need one.
    EXPECT_EQ(info.start.empty(), computed);
    if (!info.start.empty() && info.type != VariableType::string) {
      std::size_t values = 1;
      for (int i = 0; i < info.rank; ++i) values *= info.dimensions.at(static_cast<std::size_t>(i)).size;
      EXPECT_EQ(static_cast<std::size_t>(std::ranges::count(info.start, ' ')) + 1, values)
          << "start has the wrong number of values for the shape";
    }
    ASSERT_GE(info.rank, 0);
    ASSERT_LE(info.rank, 2);
    for (int i = 0; i < 2; ++i) {
      const Dimension& d = info.dimensions.at(static_cast<std::size_t>(i));
      if (i >= info.rank) {
        EXPECT_TRUE(d.size == 0 && d.size_vr == -1) << "dimension " << i << " is set beyond the rank";
      } else if (d.size_vr >= 0) {
        // FMI 3.0, "Dimension": a size given by value reference names a UInt64 structural parameter.
        const VariableInfo* size = find_variable(static_cast<std::uint32_t>(d.size_vr));
        ASSERT_NE(size, nullptr) << "dimension " << i << " refers to an unknown vr " << d.size_vr;
        EXPECT_EQ(size->causality, Causality::structural_parameter) << "dimension " << i;
        EXPECT_EQ(size->type, VariableType::uint64) << "dimension " << i;
        EXPECT_EQ(d.size, 0u) << "dimension " << i << " has both a size and a value reference";
      } else {
        EXPECT_GT(d.size, 0u) << "dimension " << i << " is empty";
      }
    }
  }
}

TEST(VariableTable, SpellsTheFmiNames) {
  EXPECT_EQ(to_string(VariableType::float64), "Float64");
  EXPECT_EQ(to_string(VariableType::int32), "Int32");
  EXPECT_EQ(to_string(VariableType::uint32), "UInt32");
  EXPECT_EQ(to_string(VariableType::uint64), "UInt64");
  EXPECT_EQ(to_string(VariableType::boolean), "Boolean");
  EXPECT_EQ(to_string(VariableType::string), "String");
  EXPECT_EQ(to_string(VariableType::enumeration), "Enumeration");
  EXPECT_EQ(to_string(Causality::independent), "independent");
  EXPECT_EQ(to_string(Causality::structural_parameter), "structuralParameter");
  EXPECT_EQ(to_string(Causality::parameter), "parameter");
  EXPECT_EQ(to_string(Causality::input), "input");
  EXPECT_EQ(to_string(Causality::output), "output");
  EXPECT_EQ(to_string(Variability::fixed), "fixed");
  EXPECT_EQ(to_string(Variability::tunable), "tunable");
  EXPECT_EQ(to_string(Variability::discrete), "discrete");
  EXPECT_EQ(to_string(Variability::continuous), "continuous");
}

}  // namespace
}  // namespace tissue::fmi3
