#pragma once
// The one calibration button: a GPIO line on the robot, or the "start"
// command of the control socket (calibctl). Presses are edge events counted
// by the implementation and taken by the daemon, so a press between two polls
// is never lost and a held button counts once.
//
// Thread safety: take_presses() from one thread (the daemon loop); an
// implementation may accept presses from other threads (documented there).
// Real-time safety: take_presses() never blocks nor allocates when ok.

#include "hal/status.h"

namespace cdpr::hal {

class Button {
 public:
  virtual ~Button() = default;

  // Number of presses since the previous call (0 if none); resets the count.
  // Errors: kIoError (GPIO read failed), kInvalidState (line not open).
  virtual Result<int> take_presses() = 0;
};

}  // namespace cdpr::hal
