// run_measured (see compare_run.hpp): a session observer that times, records and compares.
#include "compare/compare_run.hpp"

#include "links/fmu_links.hpp"
#include "session/session.hpp"

#include <array>
#include <memory>
#include <span>
#include <vector>

namespace tissue::host {
namespace {

class MeasuringObserver final : public TissueStepObserver {
 public:
  MeasuringObserver(const ReferenceTrace* reference, ReferenceTrace* record) : m_record(record) {
    if (reference != nullptr) m_compare = std::make_unique<ErrorAccumulator>(*reference);
  }

  void started(Fmu3Instance& tissue) override {
    const ModelDescription& d = tissue.description();
    m_positions = d.variable("surface.vertexPositions").value_reference;
    m_energies = {d.variable("kineticEnergy").value_reference, d.variable("elasticEnergy").value_reference};
    if (const ModelVariable* iterations = d.find_variable("integrator.iterations"))
      m_iterations = iterations->value_reference;
    m_buffer.resize(tissue.array_size(d.variable("surface.vertexPositions")));
    std::vector<std::uint64_t> count;
    (void)tissue.get_uint64("surface.vertexCount", count);
    m_vertex_count = count.empty() ? 0 : static_cast<std::size_t>(count[0]);
    if (m_record != nullptr) m_record->vertex_count = m_vertex_count;
  }

  void stepped(Fmu3Instance& tissue, const TissueStepInfo& step) override {
    m_outcome.cpu_s += step.cpu_s;
    const fmi3Status status = step.result.status;
    if (status != fmi3OK && status != fmi3Warning) {
      ++m_outcome.failures;
      if (m_outcome.note.empty()) {
        m_outcome.note = std::string("doStep at t = ") + std::to_string(step.start_s) + " s: " + status_name(status) +
                         " " + tissue.log_text();
      }
    }
    if (status == fmi3Error || status == fmi3Fatal) return;  // nothing after it can be trusted
    m_outcome.simulated_s += step.reached_s - step.start_s;
    (void)tissue.get_float64(std::span<const fmi3ValueReference>(&m_positions, 1), m_buffer);
    std::array<double, 2> energy{};
    (void)tissue.get_float64(m_energies, energy);
    if (m_iterations) {
      std::array<fmi3UInt64, 1> iterations{};
      (void)tissue.get_uint64(std::span<const fmi3ValueReference>(&*m_iterations, 1), iterations);
      m_outcome.iterations = iterations[0];
    }
    const std::span<const double> original(m_buffer.data(), 3 * m_vertex_count);
    const std::array<double, 3>& force = step.contact_force_n;
    if (m_compare) m_compare->add(step.reached_s, original, force, energy[0] + energy[1]);
    if (m_record != nullptr) m_record->add(step.reached_s, original, force, energy[0] + energy[1]);
  }

  RunOutcome finish() {
    if (m_compare) m_outcome.errors = m_compare->result();
    if (!m_outcome.errors.valid && m_compare && m_outcome.note.empty()) {
      m_outcome.note = "not compared: " + m_outcome.errors.why_not;
    }
    return m_outcome;
  }

 private:
  ReferenceTrace* m_record = nullptr;
  std::unique_ptr<ErrorAccumulator> m_compare;
  fmi3ValueReference m_positions = 0;
  std::array<fmi3ValueReference, 2> m_energies{};
  std::optional<fmi3ValueReference> m_iterations;
  std::vector<double> m_buffer;
  std::size_t m_vertex_count = 0;
  RunOutcome m_outcome;
};

}  // namespace

std::optional<double> RunOutcome::cpu_s_per_sim_s() const {
  if (!(simulated_s > 0.0)) return std::nullopt;
  return cpu_s / simulated_s;
}

RunOutcome run_measured(const Scenario& scenario, const RunSpec& run, const std::filesystem::path& fmu_dir,
                        const ReferenceTrace* reference, ReferenceTrace* record) {
  if (!run.skipped.empty()) {
    RunOutcome skipped;
    skipped.note = run.skipped;
    return skipped;
  }
  MeasuringObserver observer(reference, record);
  SessionOptions options;
  options.offline = true;
  options.fmu_dir = fmu_dir;
  options.realtime_priority = false;
  options.write_outputs = false;
  options.tissue_parameter_overrides = run.parameters;
  options.tissue_observer = &observer;
  try {
    const SessionSummary summary = run_session(scenario, options);
    RunOutcome outcome = observer.finish();
    outcome.ran = true;
    if (outcome.note.empty() && !summary.first_error.empty()) outcome.note = summary.first_error;
    return outcome;
  } catch (const std::exception& error) {
    RunOutcome failed;
    failed.note = std::string("not run: ") + error.what();
    return failed;
  }
}

}  // namespace tissue::host
