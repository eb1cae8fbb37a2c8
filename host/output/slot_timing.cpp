// write_slot_timings (see slot_timing.hpp).
#include "output/slot_timing.hpp"

#include "output/session_log.hpp"

#include <fstream>
#include <stdexcept>
#include <string>

namespace tissue::host {
namespace {

const char* frame_name(SlotFrame frame, CaptureKind kind, bool before_step) {
  switch (frame) {
    case SlotFrame::none:
      return "";
    case SlotFrame::captured:
      if (before_step) return kind == CaptureKind::remeshed ? "captured remeshed before step" : "captured before step";
      return kind == CaptureKind::remeshed ? "captured remeshed" : "captured";
    case SlotFrame::deferred:
      return kind == CaptureKind::remeshed ? "deferred remeshed" : "deferred";
    case SlotFrame::dropped:
      return "dropped";
  }
  return "";
}

}  // namespace

void write_slot_timings(const std::filesystem::path& path, std::span<const SlotTiming> rows) {
  std::ofstream out(path);
  out << "slot,slots,start_late_ms,step_ms,sample_ms,frame,capture_ms,end_after_slot_ms\n";
  std::string line;
  for (const SlotTiming& r : rows) {
    line = std::to_string(r.slot) + ',' + std::to_string(r.slots) + ',';
    append_number(line, r.start_late_ms);
    line += ',';
    append_number(line, r.step_ms);
    line += ',';
    append_number(line, r.sample_ms);
    line += ',';
    line += frame_name(r.frame, r.capture_kind, r.frame_before_step);
    line += ',';
    append_number(line, r.capture_ms);
    line += ',';
    append_number(line, r.end_after_slot_ms);
    line += '\n';
    out << line;
  }
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace tissue::host
