// SessionSteps: what a session is made of, as a scheduler calls it. The session (session/) says
// what a haptic tick, a tissue step and a surface frame do; a scheduler (offline_schedule.hpp,
// realtime_schedule.hpp) says only when. In real time the haptic side runs on the haptic thread and
// the tissue side on the dynamics thread, exchanging through the session's LatestValues
// (dissertation 5.1.3); offline both run on the calling thread.
#pragma once

#include "output/surface_frame.hpp"

#include <cstdint>

namespace tissue::host {

class SessionSteps {
 public:
  virtual ~SessionSteps() = default;

  // --- haptic side (the haptic thread in real time: no allocation, no lock, no I/O) ---
  /// Tick n, at session time n * haptic period: the device read, the newest tissue sample if there
  /// is one, the HapticLoop's doStep, the force written, the tool command published, the log row.
  virtual void haptic_tick(std::uint64_t n) = 0;
  /// Real time, after tick n: the period that ended when it woke (0 for the first tick) and the
  /// deadline misses so far (the live view shows them).
  virtual void haptic_tick_timed(std::uint64_t n, double period_s, std::uint64_t deadline_misses) = 0;

  // --- tissue side (the dynamics thread in real time) ---
  /// True once a tissue step failed (an error, not a discard): no step follows.
  [[nodiscard]] virtual bool tissue_failed() const = 0;
  /// The tissue step from tissue time `time_s` over `slots` slots with the newest tool command;
  /// returns the tissue time reached (the last good time after a discard). Its sample waits for
  /// publish_tissue_sample().
  virtual double tissue_step(double time_s, int slots) = 0;
  /// Real time: whether the coming steps have the Tissue prepare a re-meshed surface after them, in
  /// the time the slot leaves idle (its surface.prepareAfterStep), for a frame read at the next
  /// slot's start.
  virtual void prepare_surface_after_step(bool prepare) = 0;
  /// Hands the last step's sample to the haptic side (taken at its next tick).
  virtual void publish_tissue_sample() = 0;
  /// Real time, after publish_tissue_sample() (the live view's figures and frame).
  virtual void tissue_sample_published(double time_s) = 0;

  // --- the recording's surface frames (tissue side) ---
  /// True when the recording wants a frame at tissue time `time_s`.
  [[nodiscard]] virtual bool frame_due(double time_s) const = 0;
  /// Whether a capture now reads a surface re-meshed since the last one (a cut): the costly kind.
  [[nodiscard]] virtual bool frame_remeshed() = 0;
  /// Whether the re-meshed surface is still being prepared after the last step (the Tissue's
  /// surface.preparing): a capture now would wait for it.
  [[nodiscard]] virtual bool frame_preparing() = 0;
  /// The surface, tool and contact at tissue time `time_s` into `frame` (no allocation once reserved),
  /// the surface's mapping left to complete_frame().
  virtual void capture_frame(SurfaceFrame& frame, double time_s) = 0;
  /// Maps a captured frame's surface (decodes its embedding when a cut changed it): in the thread
  /// that writes the frames, out of the dynamics thread's slot. Throws like the capture.
  virtual void complete_frame(SurfaceFrame& frame) = 0;
  /// A due frame had no free buffer (the writer is behind): the recording goes on to the next one.
  virtual void frame_dropped() = 0;
  /// Gives `frame` the capacity capture_frame() needs (before the run).
  virtual void reserve_frame(SurfaceFrame& frame) = 0;

  /// Tetrahedra cut so far, for the progress lines (any thread).
  [[nodiscard]] virtual std::uint64_t cut_tets() const = 0;
};

}  // namespace tissue::host
