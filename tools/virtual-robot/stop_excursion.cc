#include "virtual-robot/stop_excursion.h"

namespace cdpr::virtual_robot {

void StopExcursion::step(double t_s, bool braking, bool drives_at_rest, const Eigen::Vector3d& platform_world,
                         double speed_mps, double offset_from_rest_m) {
  if (watching_ && !braking && !drives_at_rest && latest_->cables_stopped_s >= 0.0) {
    latest_->interrupted = true;  // the cables stopped and then moved again: a new move
    watching_ = false;
    finished_ = true;
  }
  if (!watching_ && braking && was_moving_) {
    latest_ = StopReport{};
    latest_->began_s = t_s;
    latest_->speed_mps = speed_mps;
    latest_->largest_at_s = t_s;
    start_world_ = platform_world;
    watching_ = true;
    finished_ = false;
  }
  was_moving_ = !drives_at_rest && !braking;
  if (!watching_) return;
  StopReport& r = *latest_;
  r.from_start_m = (platform_world - start_world_).norm();
  if (r.from_start_m > r.largest_m) {
    r.largest_m = r.from_start_m;
    r.largest_at_s = t_s;
  }
  if (r.cables_stopped_s < 0.0 && drives_at_rest) r.cables_stopped_s = t_s;
  if (r.cables_stopped_s >= 0.0 && speed_mps < kSettleSpeedMps && offset_from_rest_m < kSettleOffsetM) {
    r.settled = true;
    watching_ = false;
    finished_ = true;
  }
}

bool StopExcursion::take_finished() {
  const bool finished = finished_;
  finished_ = false;
  return finished;
}

}  // namespace cdpr::virtual_robot
