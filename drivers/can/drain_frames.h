#pragma once
// The receive half of a winch bank's update(): takes what the bus has
// queued, without waiting, and hands each frame on. Shared by the CANopen
// master (CanopenWinchBank) and the watch-mode listener (ListeningWinchBank),
// which differ only in what they do with a frame.
//
// Real-time safety: never blocks (receive(…, 0)), allocates nothing.

#include "drivers/can/can_transport.h"
#include "hal/winch_bank.h"

namespace cdpr::drivers::can {

// Receives at most `max_frames` frames (one update's share, so a flooded
// bus cannot starve the rest of the cycle) and calls on_frame(frame) for
// each, counting it in counters.frames_rx. A malformed record
// (kCorruptData) is counted in counters.errors and skipped; any other
// transport error is counted and returned, the frames before it handled.
template <typename OnFrame>
hal::Status drain_frames(CanTransport& transport, int max_frames, hal::WinchBankCounters& counters,
                         OnFrame&& on_frame) {
  CanFrame frame;
  for (int i = 0; i < max_frames; ++i) {
    hal::Result<bool> got = transport.receive(frame, 0);
    if (!got.ok()) {
      ++counters.errors;
      if (got.status().code() == hal::ErrorCode::kCorruptData) continue;  // one bad record: skip it
      return got.status();
    }
    if (!got.value()) break;
    ++counters.frames_rx;
    on_frame(frame);
  }
  return hal::Status::Ok();
}

}  // namespace cdpr::drivers::can
