#include "drivers/button/gpio_button.h"

#ifdef CDPR_HAVE_GPIOD

#include <gpiod.h>

#include <cerrno>
#include <ctime>

#include "drivers/common/posix_status.h"

namespace cdpr::drivers::button {
namespace {

constexpr int kMaxEventsPerCall = 64;  // bounded: a chattering line cannot stall the loop

}  // namespace

hal::Result<std::unique_ptr<GpioButton>> GpioButton::open(const GpioButtonConfig& config) {
  const std::string device = "gpio " + config.chip + ":" + std::to_string(config.line_offset);
  gpiod_chip* chip = gpiod_chip_open_lookup(config.chip.c_str());
  if (chip == nullptr) return status_from_errno(errno, device, "open chip");
  gpiod_line* line = gpiod_chip_get_line(chip, config.line_offset);
  if (line == nullptr) {
    const int error_number = errno;
    gpiod_chip_close(chip);
    return status_from_errno(error_number, device, "get line");
  }
  const int flags = config.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  if (gpiod_line_request_rising_edge_events_flags(line, "cdpr-calibd", flags) != 0) {
    const int error_number = errno;
    gpiod_chip_close(chip);
    return status_from_errno(error_number, device, "request edge events");
  }
  return std::unique_ptr<GpioButton>(new GpioButton(config, chip, line));
}

GpioButton::GpioButton(const GpioButtonConfig& config, gpiod_chip* chip, gpiod_line* line)
    : config_(config), chip_(chip), line_(line) {}

GpioButton::~GpioButton() {
  gpiod_line_release(line_);
  gpiod_chip_close(chip_);
}

hal::Result<int> GpioButton::take_presses() {
  int presses = 0;
  const timespec no_wait{0, 0};
  for (int i = 0; i < kMaxEventsPerCall; ++i) {
    const int ready = gpiod_line_event_wait(line_, &no_wait);
    if (ready == 0) break;
    gpiod_line_event event;
    if (ready < 0 || gpiod_line_event_read(line_, &event) != 0) {
      return status_from_errno(errno, "gpio " + config_.chip, "read event");
    }
    const hal::TimeUs at_us = static_cast<hal::TimeUs>(event.ts.tv_sec) * 1'000'000 + event.ts.tv_nsec / 1000;
    if (last_press_us_ < 0 || at_us - last_press_us_ >= config_.debounce_us) ++presses;
    last_press_us_ = at_us;
  }
  return presses;
}

}  // namespace cdpr::drivers::button

#endif  // CDPR_HAVE_GPIOD
