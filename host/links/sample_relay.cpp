// SampleLayout and SampleRelay (see sample_relay.hpp).
#include "links/sample_relay.hpp"

#include "importer/fmu_error.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace tissue::host {
namespace {

const char* type_name(ports::SampleType type) { return type == ports::SampleType::boolean ? "Boolean" : "Float64"; }

const ModelVariable& checked_variable(const ModelDescription& description, std::string_view name,
                                      ports::SampleType type, std::string_view causality, std::uint64_t size) {
  const std::string fmu = description.model_name();
  const ModelVariable* variable = description.find_variable(name);
  if (variable == nullptr) {
    throw FmuError(fmu + " has no variable " + std::string(name) + ", a field of the tissue sample");
  }
  if (variable->type != type_name(type) || variable->causality != causality) {
    throw FmuError(fmu + "'s " + std::string(name) + " is a " + variable->type + " " + variable->causality +
                   "; the tissue sample needs a " + type_name(type) + " " + std::string(causality));
  }
  const std::size_t elements = description.array_size(*variable);
  if (elements != size) {
    throw FmuError(fmu + "'s " + std::string(name) + " has " + std::to_string(elements) +
                   " elements; the tissue sample's field has " + std::to_string(size));
  }
  return *variable;
}

}  // namespace

SampleLayout::SampleLayout(std::span<const ports::SampleField> fields, const ModelDescription& tissue,
                           const ModelDescription& haptic)
    : m_fields(fields) {
  for (const ports::SampleField& field : fields) {
    const ModelVariable& out = checked_variable(tissue, field.tissue_output, field.type, "output", field.size());
    const ModelVariable& in = checked_variable(haptic, field.haptic_input, field.type, "input", field.size());
    SampleSlot slot{field.type, 0, static_cast<std::size_t>(field.size())};
    if (field.type == ports::SampleType::boolean) {
      slot.offset = m_flags;
      m_flags += slot.size;
      m_tissue_flags.push_back(out.value_reference);
      m_haptic_flags.push_back(in.value_reference);
    } else {
      slot.offset = m_numbers;
      m_numbers += slot.size;
      m_tissue_numbers.push_back(out.value_reference);
      m_haptic_numbers.push_back(in.value_reference);
    }
    m_slots.push_back(slot);
  }
  if (m_flags > RelaySample::MAX_FLAGS) {
    throw FmuError("the tissue sample has " + std::to_string(m_flags) + " Boolean values, more than the host carries (" +
                   std::to_string(RelaySample::MAX_FLAGS) + ")");
  }
  m_haptic_time = checked_variable(haptic, ports::SAMPLE_TIME_INPUT, ports::SampleType::float64, "input", 1)
                      .value_reference;
}

SampleSlot SampleLayout::slot(std::string_view tissue_output) const {
  for (std::size_t k = 0; k < m_fields.size(); ++k) {
    if (m_fields[k].tissue_output == tissue_output) return m_slots[k];
  }
  throw FmuError("the tissue sample has no field " + std::string(tissue_output));
}

SampleRelay::SampleRelay(SampleLayout layout) : m_layout(std::move(layout)) {
  m_haptic_number_vrs.push_back(m_layout.haptic_time());
  m_haptic_number_vrs.insert(m_haptic_number_vrs.end(), m_layout.haptic_numbers().begin(),
                             m_layout.haptic_numbers().end());
  m_haptic_values.assign(1 + m_layout.number_count(), 0.0);
}

RelaySample SampleRelay::make_sample() const {
  RelaySample sample;
  sample.numbers.assign(m_layout.number_count(), 0.0);
  return sample;
}

void SampleRelay::read(Fmu3Instance& tissue, RelaySample& sample) const {
  (void)tissue.get_float64(m_layout.tissue_numbers(), sample.numbers);
  (void)tissue.get_boolean(m_layout.tissue_flags(), std::span(sample.flags).first(m_layout.flag_count()));
  sample.finite = std::all_of(sample.numbers.begin(), sample.numbers.end(), [](double v) { return std::isfinite(v); });
}

fmi3Status SampleRelay::write(const RelaySample& sample, Fmu3Instance& haptic) const {
  // The time and the numbers in one call (the FMU takes or refuses them together), then the flags.
  m_haptic_values[0] = sample.time_s;
  std::copy(sample.numbers.begin(), sample.numbers.end(), m_haptic_values.begin() + 1);
  const fmi3Status numbers = haptic.set_float64(m_haptic_number_vrs, m_haptic_values);
  const fmi3Status flags =
      haptic.set_boolean(m_layout.haptic_flags(), std::span(sample.flags).first(m_layout.flag_count()));
  return numbers != fmi3OK ? numbers : flags;
}

}  // namespace tissue::host
