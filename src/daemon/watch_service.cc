#include "src/daemon/watch_service.h"

#include <cstdio>

#include "src/daemon/daemon_loop.h"
#include "src/formats/samples_csv.h"
#include "src/operation/pose_output_line.h"
#include "src/store/pending_calibration.h"

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

HealthWatchOptions health_options(const DaemonConfig& c) {
  HealthWatchOptions o;
  o.clean_rests_per_false_alarm = c.operation.clean_rests_per_false_alarm;
  return o;
}

}  // namespace

WatchService::WatchService(const DaemonConfig& config, const Robot& robot, store::CalibrationStore& store,
                           std::function<void(const std::string&)> log)
    : config_(config), store_(store), log_(std::move(log)),
      watch_(robot, watch_thresholds(config), config.calibrator.equilibrium_capacity, health_options(config)) {}

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
  if (watch_.refit_due()) offer_refit();
}

bool WatchService::take_pending_offered() {
  const bool offered = pending_offered_;
  pending_offered_ = false;
  return offered;
}

void WatchService::log_finding() {
  const operation::FindingSummary& f = *watch_.status().finding;
  char size[128] = "";
  if (!f.value.empty()) std::snprintf(size, sizeof size, "%.4g +- %.2g", f.value[0], f.sigma.empty() ? 0.0 : f.sigma[0]);
  std::string alike;
  for (const std::string& name : f.alike) alike += (alike.empty() ? "" : ",") + name;
  // Text for the reader, then KEY=value fields for the journal (main.cc sends them as its fields).
  log_("calibration stale: " + f.meaning + " (" + f.term + ", " + size + "), since rest " +
       std::to_string(f.since_rest) + ", fired at rest " + std::to_string(f.fired_at_rest) +
       (f.calibration_fault ? "" : "; not a calibration fault") + (alike.empty() ? "" : "; alike: " + alike) +
       " | CDPR_STATE=calibration_stale CDPR_TERM=" + f.term + " CDPR_CABLE=" + std::to_string(f.cable) +
       " CDPR_SIZE=" + (f.value.empty() ? "0" : std::to_string(f.value[0])) +
       " CDPR_SIGMA=" + (f.sigma.empty() ? "0" : std::to_string(f.sigma[0])) +
       " CDPR_SINCE_REST=" + std::to_string(f.since_rest) + " CDPR_FIRED_AT_REST=" + std::to_string(f.fired_at_rest) +
       " CDPR_CALIBRATION_SEQ=" + std::to_string(watch_.status().calibration_seq));
}

void WatchService::offer_refit() {
  if (log_) log_finding();
  std::vector<Sample> rests;
  std::string why;
  std::optional<Calibration> refit = watch_.take_refit(rests, &why);
  operation::OperationStatus& status = watch_.mutable_status();
  if (!refit) {
    status.refit = "no re-fit offered: " + why;
    if (log_) log_("watch: " + status.refit);
    return;
  }
  refit->created = utc_now_rfc3339();
  // The existing commit flow takes it from there: `calibctl commit`, never by itself.
  const auto kept = store::PendingCalibration(store_.state_dir()).keep(*refit, formats::format_samples_csv(rests));
  if (!kept) {
    status.refit = "the re-fit could not be kept: " + kept.error().message();
    if (log_) log_("watch: " + status.refit);
    return;
  }
  status.refit = "kept in pending/ for `calibctl commit` (fitted to " + std::to_string(rests.size()) + " rests)";
  pending_offered_ = true;
  if (log_) log_("watch: re-fit from " + std::to_string(rests.size()) + " rests " + status.refit);
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
