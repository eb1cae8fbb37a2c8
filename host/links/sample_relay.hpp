// The tissue sample on its way from the Tissue FMU to the HapticLoop FMU (ports/tissue_sample.hpp):
// the layout of the sample's values, field by field, from the list of fields and the two FMUs' model
// descriptions (each field's Tissue output and HapticLoop input must exist, with the field's type and
// size); the record the host carries between its threads; and the relay that reads a record from the
// Tissue (one get per element type) and writes it to the HapticLoop (one set per type). No offset is
// kept by hand: a field added to the sample list is relayed without a change here.
#pragma once

#include "importer/fmu3_instance.hpp"
#include "importer/model_description.hpp"
#include "ports/tissue_sample.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace tissue::host {

/// Where one field's values are in a RelaySample.
struct SampleSlot {
  ports::SampleType type = ports::SampleType::float64;
  std::size_t offset = 0;  ///< into RelaySample::numbers or ::flags
  std::size_t size = 0;
};

/// The layout of a sample: the fields in order, each with its slot and the two value references.
class SampleLayout {
 public:
  /// Throws FmuError naming the field and the FMU when a variable is missing or of another type,
  /// causality or size than the field says.
  SampleLayout(std::span<const ports::SampleField> fields, const ModelDescription& tissue,
               const ModelDescription& haptic);

  /// The slot of the field whose Tissue output is `tissue_output`; throws FmuError if none.
  [[nodiscard]] SampleSlot slot(std::string_view tissue_output) const;
  [[nodiscard]] std::size_t number_count() const { return m_numbers; }
  [[nodiscard]] std::size_t flag_count() const { return m_flags; }
  [[nodiscard]] std::span<const ports::SampleField> fields() const { return m_fields; }
  [[nodiscard]] std::span<const fmi3ValueReference> tissue_numbers() const { return m_tissue_numbers; }
  [[nodiscard]] std::span<const fmi3ValueReference> tissue_flags() const { return m_tissue_flags; }
  [[nodiscard]] std::span<const fmi3ValueReference> haptic_numbers() const { return m_haptic_numbers; }
  [[nodiscard]] std::span<const fmi3ValueReference> haptic_flags() const { return m_haptic_flags; }
  /// The HapticLoop's sample-time input (ports::SAMPLE_TIME_INPUT).
  [[nodiscard]] fmi3ValueReference haptic_time() const { return m_haptic_time; }

 private:
  std::span<const ports::SampleField> m_fields;
  std::vector<SampleSlot> m_slots;  // per field
  std::size_t m_numbers = 0, m_flags = 0;
  std::vector<fmi3ValueReference> m_tissue_numbers, m_tissue_flags, m_haptic_numbers, m_haptic_flags;
  fmi3ValueReference m_haptic_time = 0;
};

/// One tissue sample as the host carries it between its threads (copying one into another of the same
/// layout allocates nothing), with the host's own readings of the step.
struct RelaySample {
  static constexpr std::size_t MAX_FLAGS = 16;
  double time_s = 0.0;                    ///< the tissue time the sample is for (the step's end)
  std::vector<double> numbers;            ///< the Float64 fields' values, in slot order
  std::array<bool, MAX_FLAGS> flags{};    ///< the Boolean fields' values, in slot order
  std::uint64_t cut_tets = 0, enriched_vertices = 0;
  bool finite = true;  ///< every number is finite

  [[nodiscard]] std::span<const double> values(const SampleSlot& slot) const {
    return std::span(numbers).subspan(slot.offset, slot.size);
  }
  [[nodiscard]] bool flag(const SampleSlot& slot) const { return flags[slot.offset]; }
  /// A 3-vector field as an array.
  [[nodiscard]] std::array<double, 3> vector3(const SampleSlot& slot) const {
    return {numbers[slot.offset], numbers[slot.offset + 1], numbers[slot.offset + 2]};
  }
};

/// Reads samples from a Tissue instance and writes them to a HapticLoop instance by the layout.
class SampleRelay {
 public:
  explicit SampleRelay(SampleLayout layout);

  [[nodiscard]] const SampleLayout& layout() const { return m_layout; }
  /// A record of this layout (sized once; later copies allocate nothing).
  [[nodiscard]] RelaySample make_sample() const;
  /// The sample fields of `tissue`'s outputs into `sample` (time_s and the counters are the caller's).
  void read(Fmu3Instance& tissue, RelaySample& sample) const;
  /// `sample` to `haptic`'s tissue inputs, stamped with sample.time_s. Returns the first failing status.
  /// One thread's (it fills a buffer of the relay's): no allocation.
  fmi3Status write(const RelaySample& sample, Fmu3Instance& haptic) const;

 private:
  SampleLayout m_layout;
  std::vector<fmi3ValueReference> m_haptic_number_vrs;  // the sample time's, then the numbers'
  mutable std::vector<double> m_haptic_values;          // their values (write()'s buffer)
};

}  // namespace tissue::host
