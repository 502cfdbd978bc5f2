#include "src/daemon/watch_service.h"

#include <cstdio>

#include "src/daemon/daemon_loop.h"
#include "src/operation/pose_output_line.h"

namespace cdpr::daemon {
namespace {

// The calibration's detector thresholds with watch mode's own windows: a
// production rest lasts seconds, a calibration waypoint waits minutes.
calibration::EquilibriumThresholds watch_thresholds(const DaemonConfig& c) {
  calibration::EquilibriumThresholds t = c.calibrator.equilibrium;
  t.window_us = c.operation.rest_window_us;
  t.sway_window_us = c.operation.return_window_us;
  return t;
}

}  // namespace

WatchService::WatchService(const DaemonConfig& config, const Robot& robot, store::CalibrationStore& store,
                           std::function<void(const std::string&)> log)
    : config_(config), store_(store), log_(std::move(log)),
      watch_(robot, watch_thresholds(config), config.calibrator.equilibrium_capacity, LocalizeOptions{}) {}

hal::Status WatchService::start() {
  const std::string& endpoint = config_.operation.pose_output;
  if (!endpoint.empty()) {
    auto server = PoseOutputServer::listen(endpoint.substr(5));  // "unix:" checked by the configuration
    if (!server.ok()) return server.status();
    output_ = std::move(server.value());
  }
  reload_calibration();
  return hal::Status::Ok();
}

void WatchService::reload_calibration() {
  const auto current = store_.load_current();
  if (!current) {
    watch_.set_calibration(0, std::nullopt);
    if (log_) log_("watch: the calibration cannot be read (" + current.error().message() + "): nothing to check against");
    return;
  }
  if (!*current) {
    watch_.set_calibration(0, std::nullopt);
    if (log_) log_("watch: no calibration committed: rests are seen but not checked");
    return;
  }
  watch_.set_calibration((*current)->seq, (*current)->calibration);
  if (log_) log_("watch: checking rests against calibration " + std::to_string((*current)->seq));
}

void WatchService::step(const DaemonDevices& devices, hal::TimeUs now_us) {
  if (output_) output_->service();
  operation::WatchReadings readings;
  readings.pose = devices.pose.latest();
  for (int i = 0; i < kCableCount && i < devices.winches.winch_count(); ++i) {
    const hal::WinchStatus s = devices.winches.status(i);
    if (s.position_valid && s.alive) readings.payout_m[i] = s.payout_m;
  }
  const hal::Result<hal::TensionSample> tension = devices.load_cell.read();
  if (tension.ok()) readings.tension = tension.value();
  if (const std::optional<operation::RestOutcome> outcome = watch_.step(readings, now_us)) on_rest(*outcome);
}

void WatchService::on_rest(const operation::RestOutcome& outcome) {
  const int index = outcome.rest.index;
  if (!outcome.pose) {
    if (log_) log_("watch: rest " + std::to_string(index) + " not localized: " + outcome.why);
    return;
  }
  const LocalizedPose& pose = *outcome.pose;
  if (output_) {
    // Stamped in the onboard pose source's time, as the controller's other pose stream.
    output_->broadcast(
        operation::format_pose_output(outcome.rest.source_time_us, pose.world_T_platform, pose.covariance));
  }
  if (!log_) return;
  const Eigen::Vector3d& p = pose.world_T_platform.position_world;
  const Eigen::Vector3d sigma = pose.position_sigma();
  char text[256];
  std::snprintf(text, sizeof text,
                "watch: rest %d at (%.3f, %.3f, %.3f) m, sigma (%.1f, %.1f, %.1f) mm; onboard pose %.1f sigma away",
                index, p.x(), p.y(), p.z(), 1e3 * sigma.x(), 1e3 * sigma.y(), 1e3 * sigma.z(),
                watch_.status().last ? watch_.status().last->onboard_sigmas : 0.0);
  log_(text);
}

}  // namespace cdpr::daemon
