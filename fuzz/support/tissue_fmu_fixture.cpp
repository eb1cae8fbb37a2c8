#include "support/tissue_fmu_fixture.hpp"

#include "support/promise.hpp"
#include "tissue_fmu/variables.hpp"

#include <array>
#include <cmath>
#include <string>

namespace tissue::fuzz {

namespace {

constexpr double STEP_S = 0.01;

fmi3ValueReference vr_of(std::string_view name) {
  const auto* variable = tissue_fmu::tissue_model_description().find(name);
  if (variable == nullptr) broken("the Tissue FMU has no variable", name);
  return variable->vr;
}

void require_ok(fmi3Status status, const char* call) {
  if (status != fmi3OK) broken("the fixture's call failed:", call);
}

}  // namespace

void TissueFmuFixture::log(fmi3InstanceEnvironment environment, fmi3Status, fmi3String, fmi3String message) {
  std::string& messages = static_cast<TissueFmuFixture*>(environment)->m_message;
  if (!messages.empty()) messages += " | ";
  messages += message == nullptr ? "(null)" : message;
}

TissueFmuFixture::TissueFmuFixture() {
  const std::string token(tissue_fmu::INSTANTIATION_TOKEN);
  m_instance = fmi3InstantiateCoSimulation("fuzz", token.c_str(), TISSUE_MESH_DIR, fmi3False, fmi3False, fmi3False,
                                           fmi3False, nullptr, 0, this, &TissueFmuFixture::log, nullptr);
  if (m_instance == nullptr) broken("the Tissue FMU did not instantiate:", m_message);
  const fmi3ValueReference mesh = vr_of("mesh");
  const fmi3String beam = TISSUE_MESH_DIR "/beam_10x2x2.veg";
  require_ok(fmi3SetString(m_instance, &mesh, 1, &beam, 1), "fmi3SetString(mesh)");
  require_ok(fmi3EnterInitializationMode(m_instance, fmi3False, 0.0, 0.0, fmi3False, 0.0), "fmi3EnterInitializationMode");
  require_ok(fmi3ExitInitializationMode(m_instance), "fmi3ExitInitializationMode");
  // A vertical scalpel drawn across the beam at 60% of its length, then lifted.
  for (int n = 0; n <= 30; ++n) require_ok(step(0.06, -0.005 + 0.001 * n, -0.01, 2), "fmi3DoStep (stroke)");
  require_ok(step(0.06, 0.03, 0.05, 0), "fmi3DoStep (lifted)");
  require_ok(fmi3GetFMUState(m_instance, &m_baseline), "fmi3GetFMUState");
}

TissueFmuFixture::~TissueFmuFixture() {
  fmi3FreeFMUState(m_instance, &m_baseline);
  fmi3FreeInstance(m_instance);
}

fmi3Status TissueFmuFixture::step(double x_m, double y_m, double z_m, std::int64_t mode) {
  static const fmi3ValueReference position = vr_of("tool.position");
  static const fmi3ValueReference tool_mode = vr_of("tool.mode");
  const std::array<double, 3> p{x_m, y_m, z_m};
  if (fmi3SetFloat64(m_instance, &position, 1, p.data(), 3) != fmi3OK) return fmi3Error;
  if (fmi3SetInt64(m_instance, &tool_mode, 1, &mode, 1) != fmi3OK) return fmi3Error;
  static const fmi3ValueReference time = vr_of("time");
  fmi3Float64 time_s = 0.0;  // the instance's own (a restored state brings its time)
  if (fmi3GetFloat64(m_instance, &time, 1, &time_s, 1) != fmi3OK) return fmi3Error;
  fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
  fmi3Float64 last_s = 0.0;
  return fmi3DoStep(m_instance, time_s, STEP_S, fmi3True, &event, &terminate, &early, &last_s);
}

std::vector<std::uint8_t> TissueFmuFixture::serialized_state() {
  fmi3FMUState state = nullptr;
  require_ok(fmi3GetFMUState(m_instance, &state), "fmi3GetFMUState");
  std::size_t size = 0;
  require_ok(fmi3SerializedFMUStateSize(m_instance, state, &size), "fmi3SerializedFMUStateSize");
  std::vector<std::uint8_t> bytes(size);
  require_ok(fmi3SerializeFMUState(m_instance, state, bytes.data(), size), "fmi3SerializeFMUState");
  fmi3FreeFMUState(m_instance, &state);
  return bytes;
}

bool TissueFmuFixture::outputs_finite() {
  static const fmi3ValueReference force = vr_of("contact.force");
  std::array<double, 3> f{};
  if (fmi3GetFloat64(m_instance, &force, 1, f.data(), 3) != fmi3OK) return false;
  return std::isfinite(f[0]) && std::isfinite(f[1]) && std::isfinite(f[2]);
}

}  // namespace tissue::fuzz
