#pragma once
// The platform pose from the onboard localization system.
//
// Lifecycle: construct (configuration only) -> open() -> update()* with
// latest() between -> close(). open() again to reconnect after kNotConnected.
//
// Frames and units: position of the platform frame origin in the world frame
// [m], world_R_platform as a unit quaternion (same conventions as samples.csv).
// Time: source_time_us is the sender's own time stamp (its clock, only useful
// for differences between samples); received_us is the local monotonic time
// (hal::Clock of the driver) when the sample arrived: judge freshness with it.
// Thread safety: one thread at a time per instance. Real-time safety: update()
// with timeout_us == 0 never blocks; latest() never blocks nor allocates.

#include <cstdint>
#include <optional>

#include "hal/clock.h"
#include "hal/geometry.h"
#include "hal/status.h"

namespace cdpr::hal {

struct PoseSample {
  Vec3 platform_world;               // platform origin in world [m]
  Quaternion world_R_platform;       // unit quaternion
  bool valid = false;                // the localization's own "tracking ok" flag
  TimeUs source_time_us = 0;         // sender's time stamp [us]
  TimeUs received_us = 0;            // local monotonic time of arrival [us]
};

// Counters for diagnostics (PX4-style: counters instead of a log per line).
struct PoseSourceCounters {
  std::uint64_t samples = 0;          // well-formed samples accepted
  std::uint64_t rejected_lines = 0;   // malformed or over-long lines dropped
  std::uint64_t io_errors = 0;        // transport errors seen
};

class PoseSource {
 public:
  virtual ~PoseSource() = default;

  // Connects to the stream, or only starts connecting (a driver that must not
  // wait): update() then reports kNotConnected if the connect fails. Errors:
  // kNotConnected, kInvalidArgument (bad config).
  virtual Status open() = 0;
  // Releases the connection; safe to call twice or without open().
  virtual void close() = 0;
  // Consumes everything that has arrived, waiting at most timeout_us for the
  // first byte (0: do not wait). Malformed input is counted and dropped, never
  // an error. Errors: kNotConnected (peer closed: open() again), kIoError,
  // kInvalidState (not open). kTimeout is not an error: nothing new simply
  // leaves latest() unchanged.
  virtual Status update(TimeUs timeout_us) = 0;
  // The most recent accepted sample, valid or not; nullopt before the first.
  virtual std::optional<PoseSample> latest() const = 0;
  virtual PoseSourceCounters counters() const = 0;
};

}  // namespace cdpr::hal
