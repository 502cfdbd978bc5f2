#pragma once
// Watch mode's logic (docs/operation.md), apart from the OS
// wiring (src/daemon/watch_service.h): rests found by RestWatch, each
// checked by the health watch against the committed calibration
// (solver/operation/health_watch.h: the pose from the cables with its
// covariance, the sequential change test per term), the pose compared
// with the onboard pose in the summed covariances. When the test fires the
// state is "calibration stale" with the finding, and the re-fit from the
// rests since the change's onset (solver/operation/refit.h) is offered:
// handed to the owner, never applied here. The status is what
// `calibctl status` shows under "operation".
// Time passed in; the check runs inside step() (a small problem per rest;
// the re-fit once, when the test fires). Not thread-safe.

#include <memory>
#include <optional>
#include <vector>
#include <string>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/operation/health_watch.h"
#include "solver/operation/localize.h"
#include "solver/operation/refit.h"
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

// What the health test found (health_watch.h StaleFinding), for the status.
struct FindingSummary {
  std::string term;      // the catalogue's name: "offset[2]", "anchor[1]", "encoder_scale[0]", "load", ...
  std::string meaning;   // "encoder offset slip of cable 2"
  int cable = -1;
  std::vector<double> value, sigma;  // the term's size and its sigma (units: health_watch.h)
  int since_rest = 0;      // the change's onset
  int fired_at_rest = 0;
  hal::TimeUs fired_us = -1;
  int rests_fitted = 0;
  bool calibration_fault = true;  // false: load or centre of mass changed (no calibration fault)
  std::vector<std::string> alike;  // other terms that explain it almost as well
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
  std::optional<FindingSummary> finding;
  // The offered re-fit: "kept in pending/ for `calibctl commit`", or why none is offered.
  std::string refit;
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
                 const HealthWatchOptions& health);

  // The calibration to check against (none: nothing committed); counts start over.
  void set_calibration(int seq, std::optional<Calibration> calibration);
  std::optional<RestOutcome> step(const WatchReadings& readings, hal::TimeUs now_us);
  // Once, when the test has just fired: the re-fit to offer (empty with
  // *why when the rests cannot carry it) and the rests it used.
  bool refit_due() const { return refit_due_; }
  std::optional<Calibration> take_refit(std::vector<Sample>& rests, std::string* why);
  const OperationStatus& status() const { return status_; }
  OperationStatus& mutable_status() { return status_; }
  const std::optional<Calibration>& calibration() const { return calibration_; }

 private:
  void note_finding(const StaleFinding& finding, hal::TimeUs now_us);

  Robot robot_;
  HealthWatchOptions health_options_;
  RestWatch rests_;
  std::optional<Calibration> calibration_;
  std::unique_ptr<HealthWatch> health_;  // of calibration_
  bool refit_due_ = false;
  OperationStatus status_;
};

}  // namespace cdpr::operation
