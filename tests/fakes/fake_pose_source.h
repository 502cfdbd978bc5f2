#pragma once
// A behavioural hal::PoseSource: while streaming, every update() delivers one
// fresh sample of the current pose stamped with the injected clock (as a
// localization system streaming faster than the daemon polls). Stop the
// stream to make the pose go stale; mark it invalid to mimic lost tracking.

#include <functional>
#include <optional>
#include <utility>

#include "hal/clock.h"
#include "hal/pose_source.h"

namespace cdpr::fakes {

class FakePoseSource final : public hal::PoseSource {
 public:
  explicit FakePoseSource(const hal::Clock& clock) : clock_(clock) {}

  void set_pose(const hal::Vec3& platform_world, const hal::Quaternion& world_R_platform = {}) {
    platform_world_ = platform_world;
    world_R_platform_ = world_R_platform;
  }
  void set_valid(bool valid) { valid_ = valid; }
  // false: update() delivers nothing new, latest() ages.
  void set_streaming(bool streaming) { streaming_ = streaming; }
  // When set, called at every streaming update() for the sample to deliver
  // (e.g. the platform settling towards the winches' pose); its received_us is
  // overwritten with the clock's now. Overrides set_pose()/set_valid().
  void set_generator(std::function<hal::PoseSample(hal::TimeUs now_us)> generator) {
    generator_ = std::move(generator);
  }
  // The next update() fails with `error` (once).
  void fail_next_update(hal::Status error) { next_error_ = std::move(error); }

  bool is_open() const { return open_; }

  hal::Status open() override {
    open_ = true;
    return hal::Status::Ok();
  }
  void close() override { open_ = false; }

  hal::Status update(hal::TimeUs /*timeout_us*/) override {
    if (!open_) return hal::Status(hal::ErrorCode::kInvalidState, "fake pose source: not open");
    if (!next_error_.ok()) {
      ++counters_.io_errors;
      return std::exchange(next_error_, hal::Status::Ok());
    }
    if (!streaming_) return hal::Status::Ok();
    const hal::TimeUs now_us = clock_.now_us();
    hal::PoseSample sample;
    if (generator_) {
      sample = generator_(now_us);
    } else {
      sample.platform_world = platform_world_;
      sample.world_R_platform = world_R_platform_;
      sample.valid = valid_;
      sample.source_time_us = now_us;
    }
    sample.received_us = now_us;
    latest_ = sample;
    ++counters_.samples;
    return hal::Status::Ok();
  }

  std::optional<hal::PoseSample> latest() const override { return latest_; }
  hal::PoseSourceCounters counters() const override { return counters_; }

 private:
  const hal::Clock& clock_;
  hal::Vec3 platform_world_;
  hal::Quaternion world_R_platform_;
  bool valid_ = true;
  bool streaming_ = true;
  bool open_ = false;
  std::function<hal::PoseSample(hal::TimeUs)> generator_;
  hal::Status next_error_;
  std::optional<hal::PoseSample> latest_;
  hal::PoseSourceCounters counters_;
};

}  // namespace cdpr::fakes
