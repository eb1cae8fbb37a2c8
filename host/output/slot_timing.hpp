// The real-time session's slots, one row per tissue step (slots.csv): when the slot's work started
// against its slot, how long the step, the sample's hand-over and the recording's frame took, and how far
// past its slot's end the dynamics thread finished (an overrun when > 0). What summary.json counts,
// slot by slot: where an organ's overruns come from (issue 42).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>

namespace tissue::host {

/// What a capture of the recording's frame reads: the positions alone, or a surface re-meshed since
/// the last one (a cut), the costly kind.
enum class CaptureKind { positions, remeshed };

/// What became of the recording's frame in a slot.
enum class SlotFrame { none, captured, deferred, dropped };

struct SlotTiming {
  std::uint64_t slot = 0;  ///< the first slot the step covers (slot k starts k slot periods in)
  int slots = 1;           ///< slots it covers (more than one when catching up)
  double start_late_ms = 0.0;  ///< the slot's work (a frame left to it, then the step) began this late
  double step_ms = 0.0;        ///< the tissue step (the Tissue FMU's doStep and its reads)
  double sample_ms = 0.0;      ///< the sample handed to the haptic thread, the live view's and OpenIGTLink's
  SlotFrame frame = SlotFrame::none;
  CaptureKind capture_kind = CaptureKind::positions;  ///< when a frame was due
  double capture_ms = 0.0;                            ///< the recording's capture
  bool frame_before_step = false;  ///< captured at the slot's start, before the step (a frame left to it)
  double end_after_slot_ms = 0.0;  ///< finished this long after the covered slots' end (< 0: before)
};

/// The rows as slots.csv (with its header). Throws std::runtime_error if the file cannot be written.
void write_slot_timings(const std::filesystem::path& path, std::span<const SlotTiming> rows);

}  // namespace tissue::host
