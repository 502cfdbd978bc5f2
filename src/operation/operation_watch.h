#pragma once
// Watch mode's logic (docs/operation-watch-mode.md), apart from the OS
// wiring (src/daemon/watch_service.h): rests found by RestWatch, each
// localized from the cables with the committed calibration
// (solver/operation/localize.h, the calibration as priors), and compared
// with the onboard pose in the localization's own covariance plus the
// onboard pose's sigmas. The status is what `calibctl status` shows under
// "operation".
// Time passed in; the localization runs inside step() (a small problem,
// milliseconds). Not thread-safe.

#include <optional>
#include <string>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/operation/localize.h"
#include "src/operation/rest_watch.h"

namespace cdpr::operation {

// The last rest's pose from the cables, for the status.
struct LocalizedRestSummary {
  int rest = 0;
  hal::TimeUs seen_us = -1;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_sigma_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d orientation_sigma_rad = Eigen::Vector3d::Zero();
  // Distance of the onboard pose from it in sigmas (sqrt of the Mahalanobis
  // distance in the summed covariances, 6 degrees of freedom).
  double onboard_sigmas = 0.0;
};

struct OperationStatus {
  // "no calibration" (nothing committed to check against), "waiting for a
  // rest", "watching" (the last rest agreed), "calibration stale" (the
  // health test fired: finding says what).
  std::string state = "no calibration";
  int calibration_seq = 0;  // the calibration checked against
  int rests = 0;            // rests seen since start (or since the calibration changed)
  int localized = 0;        // of them, localized from the cables
  std::string last_problem; // why the last rest could not be localized ("" when it was)
  std::string detail;       // the rest detector's verdict now
  std::optional<LocalizedRestSummary> last;
};

// One rest and what became of it.
struct RestOutcome {
  WatchedRest rest;
  std::optional<LocalizedPose> pose;  // none: `why`
  std::string why;
};

class OperationWatch {
 public:
  OperationWatch(const Robot& robot, const calibration::EquilibriumThresholds& thresholds, std::size_t capacity,
                 const LocalizeOptions& localize);

  // The calibration to check against (none: nothing committed); counts start over.
  void set_calibration(int seq, std::optional<Calibration> calibration);
  std::optional<RestOutcome> step(const WatchReadings& readings, hal::TimeUs now_us);
  const OperationStatus& status() const { return status_; }
  OperationStatus& mutable_status() { return status_; }
  const std::optional<Calibration>& calibration() const { return calibration_; }

 private:
  Robot robot_;
  LocalizeOptions localize_;
  RestWatch rests_;
  std::optional<Calibration> calibration_;
  std::optional<Pose> previous_;  // the last localized pose: the next start
  OperationStatus status_;
};

}  // namespace cdpr::operation
