// The FMI 2.0 variants of the FMUs (fmu_src/fmi2/): their modelDescription.xml validates against
// the FMI 2.0 schema and lists the scalar layout of the port schema; and the packaged 2.0 Tissue and
// HapticLoop, loaded beside the 3.0 ones, give bitwise the same outputs for the same inputs (the same
// model behind a different call shape), keep FMU states (get/set and serialize) bitwise, take a
// quaternion set one element at a time through zero, and refuse bad calls with fmi2Error.
#include "fmi2/model_description_xml.hpp"
#include "fmi2/scalar_layout.hpp"
#include "haptic_loop/variables.hpp"
#include "ssp/system_structure.hpp"
#include "tissue_fmu/variables.hpp"

#include "fmi2_abi.h"
#include "fmi3_abi.h"

#include <dlfcn.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using tissue::fmi2::Scalar;
using tissue::fmi2::ScalarLayout;
using tissue::fmi2::ScalarType;
using tissue::fmi3::Causality;
using tissue::fmi3::VariableType;

const std::filesystem::path FMUS = TISSUE_FMU_DIR;
const std::filesystem::path SCHEMA = TISSUE_FMI2_SCHEMA_DIR;

std::string messages;  // what the FMUs logged, for failure messages
void log2(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String format, ...) {
  va_list args;
  va_start(args, format);
  std::array<char, 2048> text{};
  std::vsnprintf(text.data(), text.size(), format, args);
  va_end(args);
  messages += std::string(text.data()) + "\n";
}
void log3(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String message) {
  messages += std::string(message) + "\n";
}
const fmi2CallbackFunctions CALLBACKS{log2, nullptr, nullptr, nullptr, nullptr};

struct Library {
  void* handle = nullptr;
  explicit Library(const std::filesystem::path& file) : handle(dlopen(file.c_str(), RTLD_NOW | RTLD_LOCAL)) {}
  ~Library() {
    if (handle != nullptr) dlclose(handle);
  }
  template <class F>
  F* get(const char* name) const {
    return reinterpret_cast<F*>(dlsym(handle, name));
  }
};

// One FMU as both variants: the 2.0 component and the 3.0 instance side by side.
struct Pair {
  const ScalarLayout& layout;
  Library lib2, lib3;
  fmi2Component c2 = nullptr;
  fmi3Instance c3 = nullptr;

  Pair(const ScalarLayout& l, const std::string& id)
      : layout(l),
        lib2(FMUS / "fmi2" / id / "binaries/linux64" / (id + ".so")),
        lib3(FMUS / id / "binaries/x86_64-linux" / (id + ".so")) {
    const std::string token(l.description().instantiation_token);
    const std::string uri2 = "file://" + (FMUS / "fmi2" / id / "resources").string();
    const std::string path3 = (FMUS / id / "resources").string() + "/";
    if (lib2.handle == nullptr || lib3.handle == nullptr) return;
    c2 = lib2.get<fmi2InstantiateTYPE>("fmi2Instantiate")("two", fmi2CoSimulation, token.c_str(), uri2.c_str(),
                                                          &CALLBACKS, fmi2False, fmi2False);
    c3 = lib3.get<fmi3InstantiateCoSimulationTYPE>("fmi3InstantiateCoSimulation")(
        "three", token.c_str(), path3.c_str(), fmi3False, fmi3False, fmi3False, fmi3False, nullptr, 0, nullptr, log3,
        nullptr);
  }
  ~Pair() {
    if (c2 != nullptr) lib2.get<fmi2FreeInstanceTYPE>("fmi2FreeInstance")(c2);
    if (c3 != nullptr) lib3.get<fmi3FreeInstanceTYPE>("fmi3FreeInstance")(c3);
  }
  [[nodiscard]] bool ready() const { return c2 != nullptr && c3 != nullptr; }

  fmi2Status start2() {
    if (lib2.get<fmi2SetupExperimentTYPE>("fmi2SetupExperiment")(c2, fmi2False, 0, 0.0, fmi2False, 0) != fmi2OK) {
      return fmi2Error;
    }
    const fmi2Status s = lib2.get<fmi2EnterInitializationModeTYPE>("fmi2EnterInitializationMode")(c2);
    return s != fmi2OK ? s : lib2.get<fmi2ExitInitializationModeTYPE>("fmi2ExitInitializationMode")(c2);
  }
  fmi3Status start3() {
    const fmi3Status s =
        lib3.get<fmi3EnterInitializationModeTYPE>("fmi3EnterInitializationMode")(c3, fmi3False, 0, 0.0, fmi3False, 0);
    return s != fmi3OK ? s : lib3.get<fmi3ExitInitializationModeTYPE>("fmi3ExitInitializationMode")(c3);
  }
  fmi2Status step2(double t, double h) { return lib2.get<fmi2DoStepTYPE>("fmi2DoStep")(c2, t, h, fmi2True); }
  fmi3Status step3(double t, double h) {
    fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
    fmi3Float64 last = 0.0;
    return lib3.get<fmi3DoStepTYPE>("fmi3DoStep")(c3, t, h, fmi3True, &event, &terminate, &early, &last);
  }

  [[nodiscard]] fmi2ValueReference vr2(const std::string& name) const {
    for (std::size_t k = 0; k < layout.scalars().size(); ++k) {
      if (layout.scalars()[k].name == name) return static_cast<fmi2ValueReference>(k);
    }
    ADD_FAILURE() << "no scalar " << name;
    return 0;
  }
  // Sets a Real array variable in both (2.0 element by element, as FMPy and fmusim do).
  // The 2.0 value reference of a variable's first element (its elements follow in row-major order).
  [[nodiscard]] fmi2ValueReference first_vr2(const std::string& name) const {
    for (std::size_t k = 0; k < layout.scalars().size(); ++k) {
      if (layout.scalars()[k].variable->name == name) return static_cast<fmi2ValueReference>(k);
    }
    ADD_FAILURE() << "no variable " << name;
    return 0;
  }
  void set_real(const std::string& name, const std::vector<double>& values) {
    const fmi2ValueReference first = first_vr2(name);
    for (std::size_t e = 0; e < values.size(); ++e) {
      const auto vr = static_cast<fmi2ValueReference>(first + e);
      EXPECT_EQ(lib2.get<fmi2SetRealTYPE>("fmi2SetReal")(c2, &vr, 1, &values[e]), fmi2OK)
          << layout.scalars()[vr].name << messages;
    }
    const fmi3ValueReference vr3 = layout.scalars()[first].variable->vr;
    EXPECT_EQ(lib3.get<fmi3SetFloat64TYPE>("fmi3SetFloat64")(c3, &vr3, 1, values.data(), values.size()), fmi3OK);
  }
  void set_boolean(const std::string& name, bool value) {
    const fmi2ValueReference vr = vr2(name);
    const fmi2Boolean v2 = value ? fmi2True : fmi2False;
    EXPECT_EQ(lib2.get<fmi2SetBooleanTYPE>("fmi2SetBoolean")(c2, &vr, 1, &v2), fmi2OK) << messages;
    const fmi3ValueReference vr3 = layout.scalars()[vr].variable->vr;
    const fmi3Boolean v3 = value;
    EXPECT_EQ(lib3.get<fmi3SetBooleanTYPE>("fmi3SetBoolean")(c3, &vr3, 1, &v3, 1), fmi3OK);
  }
  void set_enumeration(const std::string& name, int value) {
    const fmi2ValueReference vr = vr2(name);
    EXPECT_EQ(lib2.get<fmi2SetIntegerTYPE>("fmi2SetInteger")(c2, &vr, 1, &value), fmi2OK) << messages;
    const fmi3ValueReference vr3 = layout.scalars()[vr].variable->vr;
    const fmi3Int64 v = value;
    EXPECT_EQ(lib3.get<fmi3SetInt64TYPE>("fmi3SetInt64")(c3, &vr3, 1, &v, 1), fmi3OK);
  }

  // Every output scalar of the 2.0 component against the same element of the 3.0 instance: equal
  // bit for bit (Reals compared as bytes). Returns how many differ.
  int compare_outputs(const std::string& when) {
    int differ = 0;
    for (std::size_t k = 0; k < layout.scalars().size(); ++k) {
      const Scalar& s = layout.scalars()[k];
      if (s.variable->causality != Causality::output) continue;
      const auto vr = static_cast<fmi2ValueReference>(k);
      const fmi3ValueReference vr3 = s.variable->vr;
      const std::size_t n = ScalarLayout::element_count(*s.variable);
      if (s.type == ScalarType::real) {
        fmi2Real v2 = 0;
        std::vector<fmi3Float64> v3(n);
        lib2.get<fmi2GetRealTYPE>("fmi2GetReal")(c2, &vr, 1, &v2);
        lib3.get<fmi3GetFloat64TYPE>("fmi3GetFloat64")(c3, &vr3, 1, v3.data(), n);
        if (std::memcmp(&v2, &v3[s.element], sizeof(double)) != 0) {
          ++differ;
          ADD_FAILURE() << when << ": " << s.name << " 2.0 " << v2 << " 3.0 " << v3[s.element];
        }
      } else if (s.type == ScalarType::boolean) {
        fmi2Boolean v2 = 0;
        fmi3Boolean v3 = false;
        lib2.get<fmi2GetBooleanTYPE>("fmi2GetBoolean")(c2, &vr, 1, &v2);
        lib3.get<fmi3GetBooleanTYPE>("fmi3GetBoolean")(c3, &vr3, 1, &v3, 1);
        if ((v2 != 0) != v3) {
          ++differ;
          ADD_FAILURE() << when << ": " << s.name;
        }
      } else if (s.type == ScalarType::integer || s.type == ScalarType::enumeration) {
        fmi2Integer v2 = 0;
        std::int64_t v3 = 0;
        lib2.get<fmi2GetIntegerTYPE>("fmi2GetInteger")(c2, &vr, 1, &v2);
        if (s.variable->type == VariableType::uint64) {
          fmi3UInt64 u = 0;
          lib3.get<fmi3GetUInt64TYPE>("fmi3GetUInt64")(c3, &vr3, 1, &u, 1);
          v3 = static_cast<std::int64_t>(u);
        } else if (s.variable->type == VariableType::uint32) {
          fmi3UInt32 u = 0;
          lib3.get<fmi3GetUInt32TYPE>("fmi3GetUInt32")(c3, &vr3, 1, &u, 1);
          v3 = u;
        } else {
          lib3.get<fmi3GetInt64TYPE>("fmi3GetInt64")(c3, &vr3, 1, &v3, 1);
        }
        if (v2 != v3) {
          ++differ;
          ADD_FAILURE() << when << ": " << s.name << " 2.0 " << v2 << " 3.0 " << v3;
        }
      }
    }
    return differ;
  }
};

const ScalarLayout& tissue_layout() {
  static const ScalarLayout layout(tissue::tissue_fmu::tissue_model_description());
  return layout;
}
const ScalarLayout& haptic_layout() {
  static const ScalarLayout layout(tissue::haptic_fmu::haptic_loop_model_description());
  return layout;
}

std::string read_file(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(Fmi2Description, BothValidateAgainstTheFmi2SchemaAndAreTheLayoutsXml) {
  if (!std::filesystem::exists(SCHEMA / "fmi2ModelDescription.xsd")) GTEST_SKIP() << "no FMI 2.0 schema at " << SCHEMA;
  for (const auto& [id, layout] : {std::pair{"Tissue", &tissue_layout()}, std::pair{"HapticLoop", &haptic_layout()}}) {
    const std::filesystem::path xml = FMUS / "fmi2" / id / "modelDescription.xml";
    EXPECT_EQ(read_file(xml), tissue::fmi2::model_description_xml(*layout)) << xml;
    const std::string command =
        "xmllint --noout --schema " + (SCHEMA / "fmi2ModelDescription.xsd").string() + " " + xml.string() + " 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
  }
}

TEST(Fmi2Layout, ArraysAreIndexedScalarsAndWhatFmi2CannotCarryIsLeftOut) {
  const ScalarLayout& layout = tissue_layout();
  std::vector<std::string> names;
  for (const Scalar& s : layout.scalars()) names.push_back(s.name);
  const auto has = [&](const std::string& name) { return std::find(names.begin(), names.end(), name) != names.end(); };
  EXPECT_TRUE(has("gravity[3]"));
  EXPECT_TRUE(has("contact.stiffness[2,3]"));
  EXPECT_TRUE(has("tool.orientation[4]"));
  EXPECT_TRUE(has("sample.time"));
  EXPECT_FALSE(has("surface.mesh"));                  // Binary
  EXPECT_FALSE(has("surface.vertexCapacity"));        // structural parameter
  EXPECT_FALSE(has("surface.vertexPositions[1,1]"));  // sized by one
  const Scalar& k23 = layout.scalars()[static_cast<std::size_t>(
      std::find(names.begin(), names.end(), "contact.stiffness[2,3]") - names.begin())];
  EXPECT_EQ(k23.element, 5u);  // row-major
  EXPECT_EQ(layout.find(static_cast<std::uint32_t>(names.size())), nullptr);
}

// The frog pressed by the probe: 40 steps of 10 ms, the probe from 1 cm above the back 3 mm into it.
TEST(Fmi2Tissue, GivesTheFmi3TissuesOutputsBitForBitAndKeepsItsStates) {
  Pair tissue(tissue_layout(), "Tissue");
  ASSERT_TRUE(tissue.ready()) << messages << dlerror();
  tissue.set_real("stepSize", {0.01});
  ASSERT_EQ(tissue.start2(), fmi2OK) << messages;
  ASSERT_EQ(tissue.start3(), fmi3OK) << messages;
  tissue.set_enumeration("tool.mode", 1);  // probe
  const double h = 0.01;
  const auto press = [&](int n) {
    tissue.set_real("tool.position", {-0.007, 0.0, 0.046 - 0.013 * std::min(1.0, n / 30.0)});
    ASSERT_EQ(tissue.step2(n * h, h), fmi2OK) << messages;
    ASSERT_EQ(tissue.step3(n * h, h), fmi3OK) << messages;
  };
  for (int n = 0; n < 40; ++n) {
    press(n);
    ASSERT_EQ(tissue.compare_outputs("step " + std::to_string(n)), 0);
  }
  const fmi2ValueReference active = tissue.vr2("contact.active");
  fmi2Boolean in_contact = 0;
  tissue.lib2.get<fmi2GetBooleanTYPE>("fmi2GetBoolean")(tissue.c2, &active, 1, &in_contact);
  EXPECT_EQ(in_contact, fmi2True) << "the press did not reach the frog";

  // FMU state: taken at step 40, ten more steps, back, the same ten again: bitwise the same.
  auto& lib = tissue.lib2;
  fmi2FMUstate state = nullptr;
  ASSERT_EQ(lib.get<fmi2GetFMUstateTYPE>("fmi2GetFMUstate")(tissue.c2, &state), fmi2OK) << messages;
  const fmi2ValueReference fz = tissue.vr2("contact.force[3]");
  std::vector<double> first, again, from_bytes;
  const auto run10 = [&](std::vector<double>& forces) {
    for (int n = 40; n < 50; ++n) {
      const double z = 0.033 - 0.0002 * (n - 40);
      const std::array<fmi2ValueReference, 3> p{tissue.vr2("tool.position[1]"), tissue.vr2("tool.position[2]"),
                                                tissue.vr2("tool.position[3]")};
      const std::array<double, 3> v{-0.007, 0.0, z};
      ASSERT_EQ(lib.get<fmi2SetRealTYPE>("fmi2SetReal")(tissue.c2, p.data(), 3, v.data()), fmi2OK);
      ASSERT_EQ(tissue.step2(n * h, h), fmi2OK) << messages;
      double f = 0.0;
      lib.get<fmi2GetRealTYPE>("fmi2GetReal")(tissue.c2, &fz, 1, &f);
      forces.push_back(f);
    }
  };
  run10(first);
  ASSERT_EQ(lib.get<fmi2SetFMUstateTYPE>("fmi2SetFMUstate")(tissue.c2, state), fmi2OK) << messages;
  run10(again);
  EXPECT_EQ(first, again);
  std::size_t size = 0;
  ASSERT_EQ(lib.get<fmi2SerializedFMUstateSizeTYPE>("fmi2SerializedFMUstateSize")(tissue.c2, state, &size), fmi2OK);
  std::vector<fmi2Byte> bytes(size);
  ASSERT_EQ(lib.get<fmi2SerializeFMUstateTYPE>("fmi2SerializeFMUstate")(tissue.c2, state, bytes.data(), size), fmi2OK);
  fmi2FMUstate restored = nullptr;
  ASSERT_EQ(lib.get<fmi2DeSerializeFMUstateTYPE>("fmi2DeSerializeFMUstate")(tissue.c2, bytes.data(), size, &restored),
            fmi2OK)
      << messages;
  ASSERT_EQ(lib.get<fmi2SetFMUstateTYPE>("fmi2SetFMUstate")(tissue.c2, restored), fmi2OK) << messages;
  run10(from_bytes);
  EXPECT_EQ(first, from_bytes);
  EXPECT_GT(first.back(), 0.1) << "the probe should push on the frog";
  lib.get<fmi2FreeFMUstateTYPE>("fmi2FreeFMUstate")(tissue.c2, &state);
  lib.get<fmi2FreeFMUstateTYPE>("fmi2FreeFMUstate")(tissue.c2, &restored);
  EXPECT_EQ(state, nullptr);
}

TEST(Fmi2HapticLoop, GivesTheFmi3HapticLoopsOutputsBitForBit) {
  messages.clear();
  Pair haptic(haptic_layout(), "HapticLoop");
  ASSERT_TRUE(haptic.ready()) << messages << dlerror();
  ASSERT_EQ(haptic.start2(), fmi2OK) << messages;
  ASSERT_EQ(haptic.start3(), fmi3OK) << messages;
  haptic.set_enumeration("device.toolMode", 1);
  // A contact plane at z = 0 sampled once; the device moves down through it at 1 kHz.
  haptic.set_real("tissue.time", {0.0});
  haptic.set_boolean("tissue.contactActive", true);
  haptic.set_real("tissue.contactNormal", {0.0, 0.0, 1.0});
  haptic.set_real("tissue.contactStiffness", {0, 0, 0, 0, 0, 0, 0, 0, 300.0});
  for (int n = 0; n < 200; ++n) {
    haptic.set_real("device.position", {0.001, 0.0, 0.002 - 0.00002 * n});
    ASSERT_EQ(haptic.step2(n * 1e-3, 1e-3), fmi2OK) << messages;
    ASSERT_EQ(haptic.step3(n * 1e-3, 1e-3), fmi3OK) << messages;
    ASSERT_EQ(haptic.compare_outputs("tick " + std::to_string(n)), 0);
  }
  const fmi2ValueReference fz = haptic.vr2("device.force[3]");
  double force_z = 0.0;
  haptic.lib2.get<fmi2GetRealTYPE>("fmi2GetReal")(haptic.c2, &fz, 1, &force_z);
  EXPECT_GT(force_z, 0.1) << "the device below the contact plane should be pushed up";
}

TEST(Fmi2Tissue, AQuaternionSetOneElementAtATimeMayPassThroughZero) {
  Pair tissue(tissue_layout(), "Tissue");
  ASSERT_TRUE(tissue.ready());
  auto& lib = tissue.lib2;
  ASSERT_EQ(tissue.start2(), fmi2OK) << messages;
  // (1, 0, 0, 0) to (0, 1, 0, 0), w first: the value is (0, 0, 0, 0) in between.
  const fmi2ValueReference w = tissue.vr2("tool.orientation[1]"), x = tissue.vr2("tool.orientation[2]");
  const double zero = 0.0, one = 1.0;
  ASSERT_EQ(lib.get<fmi2SetRealTYPE>("fmi2SetReal")(tissue.c2, &w, 1, &zero), fmi2OK) << messages;
  double read_back = -1.0;
  lib.get<fmi2GetRealTYPE>("fmi2GetReal")(tissue.c2, &w, 1, &read_back);
  EXPECT_EQ(read_back, 0.0) << "a value held until it is whole still reads back as set";
  ASSERT_EQ(lib.get<fmi2SetRealTYPE>("fmi2SetReal")(tissue.c2, &x, 1, &one), fmi2OK) << messages;
  EXPECT_EQ(tissue.step2(0.0, 0.01), fmi2OK) << messages;
  // Left at zero, the next step refuses it, naming it.
  ASSERT_EQ(lib.get<fmi2SetRealTYPE>("fmi2SetReal")(tissue.c2, &x, 1, &zero), fmi2OK) << messages;
  messages.clear();
  EXPECT_EQ(tissue.step2(0.01, 0.01), fmi2Error);
  EXPECT_NE(messages.find("tool.orientation"), std::string::npos) << messages;
}

TEST(Fmi2Tissue, BadCallsAreRefusedWithTheReason) {
  Library lib(FMUS / "fmi2/Tissue/binaries/linux64/Tissue.so");
  ASSERT_NE(lib.handle, nullptr);
  const auto instantiate = lib.get<fmi2InstantiateTYPE>("fmi2Instantiate");
  const std::string token(tissue_layout().description().instantiation_token);
  const std::string uri = "file://" + (FMUS / "fmi2/Tissue/resources").string();
  messages.clear();
  EXPECT_EQ(instantiate("t", fmi2CoSimulation, "{wrong}", uri.c_str(), &CALLBACKS, 0, 0), nullptr);
  EXPECT_NE(messages.find("GUID"), std::string::npos) << messages;
  EXPECT_EQ(instantiate("t", fmi2ModelExchange, token.c_str(), uri.c_str(), &CALLBACKS, 0, 0), nullptr);
  EXPECT_EQ(instantiate("t", fmi2CoSimulation, token.c_str(), uri.c_str(), nullptr, 0, 0), nullptr);
  EXPECT_EQ(instantiate("t", fmi2CoSimulation, token.c_str(), "http://example.com/r", &CALLBACKS, 0, 0), nullptr);
  fmi2Component c = instantiate("t", fmi2CoSimulation, token.c_str(), uri.c_str(), &CALLBACKS, 0, 0);
  ASSERT_NE(c, nullptr) << messages;
  const fmi2ValueReference time_vr = 0, mode = static_cast<fmi2ValueReference>(tissue_layout().scalars().size() - 1);
  double value = 0.0;
  messages.clear();
  EXPECT_EQ(lib.get<fmi2GetRealTYPE>("fmi2GetReal")(c, &time_vr, 1, &value), fmi2Error) << "before initialization";
  EXPECT_EQ(lib.get<fmi2DoStepTYPE>("fmi2DoStep")(c, 0.0, 0.01, 1), fmi2Error);
  EXPECT_EQ(lib.get<fmi2ResetTYPE>("fmi2Reset")(c), fmi2OK);  // out of the error state
  EXPECT_EQ(lib.get<fmi2EnterInitializationModeTYPE>("fmi2EnterInitializationMode")(c), fmi2OK) << messages;
  int integer = 0;
  EXPECT_EQ(lib.get<fmi2GetIntegerTYPE>("fmi2GetInteger")(c, &time_vr, 1, &integer), fmi2Error) << "time is a Real";
  EXPECT_NE(messages.find("not Integer"), std::string::npos) << messages;
  const fmi2ValueReference unknown = 100000;
  EXPECT_EQ(lib.get<fmi2GetRealTYPE>("fmi2GetReal")(c, &unknown, 1, &value), fmi2Error);
  EXPECT_EQ(lib.get<fmi2SetRealTYPE>("fmi2SetReal")(c, &time_vr, 1, &value), fmi2Error) << "time cannot be set";
  (void)mode;
  lib.get<fmi2FreeInstanceTYPE>("fmi2FreeInstance")(c);
}

// The SSP wires every tissue input of the haptic loop (the sample and its time) and the tool back
// to the tissue, from the same port lists; the build's SystemStructure.ssd is its text.
TEST(Fmi2Ssp, EveryTissueInputOfTheHapticLoopIsConnectedOnceAndTheToolGoesBack) {
  const std::vector<tissue::ssp::Connection> all = tissue::ssp::connections(tissue_layout(), haptic_layout());
  std::map<std::string, int> ends;
  for (const auto& c : all) ++ends[c.end_element + "." + c.end_connector];
  for (const Scalar& s : haptic_layout().scalars()) {
    if (s.variable->causality == Causality::input && s.name.rfind("tissue.", 0) == 0) {
      EXPECT_EQ(ends["HapticLoop." + s.name], 1) << s.name;
    }
  }
  EXPECT_EQ(ends["HapticLoop.tissue.time"], 1);
  for (const char* tool : {"Tissue.tool.position[1]", "Tissue.tool.position[3]", "Tissue.tool.mode"}) {
    EXPECT_EQ(ends[tool], 1) << tool;
  }
  EXPECT_EQ(ends["HapticLoop.device.toolMode"], 1);
  EXPECT_EQ(ends[".device.force[3]"], 1) << "the force to the hand is a system output";
  EXPECT_EQ(read_file(std::filesystem::path(TISSUE_SSP_DIR) / "TissueHaptic/SystemStructure.ssd"),
            tissue::ssp::system_structure_ssd(tissue_layout(), haptic_layout()));
}

}  // namespace
