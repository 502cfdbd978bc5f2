#pragma once
// How far the platform goes after a stop: the figure an integrator plans a
// keep-out zone with. A stop begins when a drive starts braking to rest
// (quick stop, fault reaction, halt) while the winches move; from then the
// platform's largest distance from where it was at that moment is kept,
// until it is at rest (slower than settle_speed_mps and within
// settle_offset_m of its rest pose) or the next move starts.
// The cables stop within a second or two; the platform, a heavy pendulum on
// long cables, swings on about its new rest pose for much longer, so the
// largest excursion is usually reached half a sway period after the stop.
// Time: robot (simulated) seconds passed in; no clock read. Not thread-safe.

#include <optional>

#include <Eigen/Core>

namespace cdpr::virtual_robot {

struct StopReport {
  double began_s = 0.0;           // robot time the first drive began to brake [s]
  double speed_mps = 0.0;         // platform speed then [m/s]
  double largest_m = 0.0;         // largest distance from the platform's position then [m]
  double largest_at_s = 0.0;      // robot time of that largest distance [s]
  double from_start_m = 0.0;      // distance from it at the latest step (at rest: where it rests) [m]
  double cables_stopped_s = -1.0; // robot time every drive was at rest again; -1: not yet [s]
  bool settled = false;           // the platform came to rest
  bool interrupted = false;       // a new move began before it did
};

class StopExcursion {
 public:
  static constexpr double kSettleSpeedMps = 0.01;
  static constexpr double kSettleOffsetM = 0.01;

  // One step at robot time t_s: whether a drive is braking to a stop, whether
  // every drive is at rest, where the platform is [m, world], how fast it
  // moves [m/s] and how far it is from its rest pose [m].
  void step(double t_s, bool braking, bool drives_at_rest, const Eigen::Vector3d& platform_world, double speed_mps,
            double offset_from_rest_m);
  // The latest stop, or none before the first.
  const std::optional<StopReport>& latest() const { return latest_; }
  // True once per stop, at the step that ended its watch (settled or
  // interrupted): the moment to report it.
  bool take_finished();

 private:
  std::optional<StopReport> latest_;
  Eigen::Vector3d start_world_ = Eigen::Vector3d::Zero();
  bool watching_ = false;
  bool finished_ = false;
  bool was_moving_ = false;
};

}  // namespace cdpr::virtual_robot
