#pragma once
// The device side of a CAN bus for driver loopback tests: the virtual
// robot's simulated CiA 402 drives and CiA 406 encoders (written from the
// standards without the master's code, tools/virtual-robot) on the far end
// of a real socket. Each encoder is geared to its drive (encoder counts =
// drive counts x encoder_per_drive + encoder_offset). Test time is passed
// to step(now), which handles what arrived, moves the drives by the time
// since the last step and sends what is due.

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "drivers/can/fd_can_transport.h"
#include "virtual-robot/cia402_device.h"
#include "virtual-robot/cia406_device.h"

namespace cdpr::drivers::can::test {

class FakeCanopenBus {
 public:
  struct Winch {
    std::unique_ptr<virtual_robot::Cia402Device> drive;
    std::unique_ptr<virtual_robot::Cia406Device> encoder;  // null: none
    std::int64_t encoder_per_drive = 2;
    std::int64_t encoder_offset = 1000;  // encoder counts at drive position 0
    std::uint32_t mode_shown = 0;        // 0x6061 while a mode switch is delayed
    std::uint32_t mode_written = 0;
    hal::TimeUs mode_written_us = -1;
  };

  explicit FakeCanopenBus(int fd, virtual_robot::DriveDefaults drive_defaults = {},
                          virtual_robot::EncoderDefaults encoder_defaults = {})
      : transport_(fd, "fake bus"), drive_defaults_(drive_defaults), encoder_defaults_(encoder_defaults) {}

  Winch& add(int node_id, int encoder_node_id) { return add(node_id, encoder_node_id, drive_defaults_); }
  // ... with a drive of its own (another make than the bus's others).
  Winch& add(int node_id, int encoder_node_id, const virtual_robot::DriveDefaults& drive) {
    winches_.push_back(Winch{});
    Winch& w = winches_.back();
    w.drive = std::make_unique<virtual_robot::Cia402Device>(node_id, drive);
    if (encoder_node_id != 0) w.encoder = std::make_unique<virtual_robot::Cia406Device>(encoder_node_id, encoder_defaults_);
    return w;
  }
  Winch& winch(std::size_t i) { return winches_[i]; }
  virtual_robot::Cia402Device& drive(std::size_t i) { return *winches_[i].drive; }
  virtual_robot::Cia406Device& encoder(std::size_t i) { return *winches_[i].encoder; }
  std::int64_t encoder_counts(std::size_t i) const {
    const Winch& w = winches_[i];
    return std::llround(w.drive->position_counts()) * w.encoder_per_drive + w.encoder_offset;
  }
  // Drives switch modes asynchronously: with a delay, 0x6061 shows a mode
  // written to 0x6060 only `delay_us` after the write (the virtual device
  // shows it at once).
  void set_mode_switch_delay(hal::TimeUs delay_us) { mode_switch_delay_us_ = delay_us; }
  // Every frame the devices received, in order (for tests of what the master sent).
  const std::vector<virtual_robot::BusFrame>& received() const { return received_; }

  void step(hal::TimeUs now_us) {
    CanFrame frame;
    for (;;) {
      const hal::Result<bool> got = transport_.receive(frame, 0);
      if (!got.ok() || !got.value()) break;
      const virtual_robot::BusFrame bus{frame.id, frame.len, frame.data};
      received_.push_back(bus);
      for (Winch& w : winches_) {
        w.drive->on_frame(bus, now_us);
        if (w.encoder) w.encoder->on_frame(bus, now_us);
        lag_mode_display(w, now_us);
      }
    }
    for (Winch& w : winches_) lag_mode_display(w, now_us);
    const double dt_s = last_step_us_ < 0 ? 0.0 : 1e-6 * static_cast<double>(now_us - last_step_us_);
    last_step_us_ = now_us;
    out_.clear();
    for (std::size_t i = 0; i < winches_.size(); ++i) {
      Winch& w = winches_[i];
      w.drive->advance(dt_s);
      w.drive->poll(now_us, out_);
      if (!w.encoder) continue;
      w.encoder->set_position_counts(encoder_counts(i));
      w.encoder->poll(now_us, out_);
    }
    for (const virtual_robot::BusFrame& f : out_) (void)transport_.send(CanFrame{f.id, f.len, f.data});
  }

 private:
  void lag_mode_display(Winch& w, hal::TimeUs now_us) {
    if (mode_switch_delay_us_ <= 0) return;
    auto& od = w.drive->od();
    const std::uint32_t written = od.get(0x6060, 0);
    if (w.mode_written_us < 0) {
      w.mode_shown = w.mode_written = written;
      w.mode_written_us = now_us;
    } else if (written != w.mode_written) {
      w.mode_written = written;
      w.mode_written_us = now_us;
    }
    if (now_us - w.mode_written_us >= mode_switch_delay_us_) w.mode_shown = w.mode_written;
    od.set(0x6061, 0, w.mode_shown);
  }

  FdCanTransport transport_;
  hal::TimeUs mode_switch_delay_us_ = 0;
  virtual_robot::DriveDefaults drive_defaults_;
  virtual_robot::EncoderDefaults encoder_defaults_;
  hal::TimeUs last_step_us_ = -1;
  std::vector<Winch> winches_;
  std::vector<virtual_robot::BusFrame> out_;
  std::vector<virtual_robot::BusFrame> received_;
};

}  // namespace cdpr::drivers::can::test
