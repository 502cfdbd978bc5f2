#pragma once
// hal::Button on a GPIO line through libgpiod (v1 API). Compiled only where
// libgpiod was found (CDPR_HAVE_GPIOD, set by drivers/CMakeLists.txt for the
// library and its users).
//
// The line is requested for edge events in the "pressed" direction
// (active_low: a button pulling the line to ground, the usual wiring);
// take_presses() reads the queued kernel events without blocking and counts
// presses at least debounce_us apart (kernel time stamps), so contact bounce
// counts once. Owns the chip and line (released in the destructor).

#ifdef CDPR_HAVE_GPIOD

#include <memory>
#include <string>

#include "hal/button.h"
#include "hal/clock.h"

struct gpiod_chip;  // libgpiod's opaque types, no <gpiod.h> here
struct gpiod_line;

namespace cdpr::drivers::button {

struct GpioButtonConfig {
  std::string chip = "gpiochip0";  // name, number or /dev path (gpiod_chip_open_lookup)
  unsigned line_offset = 0;
  bool active_low = true;
  hal::TimeUs debounce_us = 50'000;
};

class GpioButton final : public hal::Button {
 public:
  // Errors: kNotConnected (no such chip or line), kIoError (line busy, request refused).
  static hal::Result<std::unique_ptr<GpioButton>> open(const GpioButtonConfig& config);
  ~GpioButton() override;
  GpioButton(const GpioButton&) = delete;
  GpioButton& operator=(const GpioButton&) = delete;

  hal::Result<int> take_presses() override;

 private:
  GpioButton(const GpioButtonConfig& config, gpiod_chip* chip, gpiod_line* line);

  GpioButtonConfig config_;
  gpiod_chip* chip_;
  gpiod_line* line_;
  hal::TimeUs last_press_us_ = -1;
};

}  // namespace cdpr::drivers::button

#endif  // CDPR_HAVE_GPIOD
