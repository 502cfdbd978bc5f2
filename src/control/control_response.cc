#include "src/control/control_response.h"

#include <limits>

#include <Eigen/Core>

#include "src/control/json_writer.h"

namespace cdpr::control {
namespace {

JsonWriter& vector3(JsonWriter& json, const Eigen::Vector3d& v) {
  return json.begin_array().value(v.x()).value(v.y()).value(v.z()).end_array();
}

std::string line(const JsonWriter& json) { return json.text() + "\n"; }

}  // namespace

std::string format_error_response(std::string_view reason) {
  JsonWriter json;
  json.begin_object().key("ok").value(false).key("error").value(reason).end_object();
  return line(json);
}

std::string format_ok_response(std::string_view message) {
  JsonWriter json;
  json.begin_object().key("ok").value(true).key("message").value(message).end_object();
  return line(json);
}

std::string format_status_response(const calibration::CalibrationStatus& status, hal::TimeUs now_us) {
  JsonWriter json;
  json.begin_object().key("ok").value(true);
  json.key("state").value(calibration::to_string(status.state));
  json.key("running").value(calibration::is_running(status.state));
  json.key("waypoint").value(status.waypoint).key("waypoints").value(status.waypoint_count);
  json.key("samples").value(status.samples).key("skipped").value(status.skipped);
  json.key("progress").value(status.progress);
  json.key("elapsed_s");
  if (status.started_us < 0) {
    json.value(std::numeric_limits<double>::quiet_NaN());  // null
  } else {
    const hal::TimeUs end_us = status.finished_us >= 0 ? status.finished_us : now_us;
    json.value(1e-6 * static_cast<double>(end_us - status.started_us));
  }
  json.key("reason").value(status.reason).key("note").value(status.note).key("detail").value(status.detail);
  json.key("device_faults").value(status.device_faults);
  json.key("committed_seq").value(status.committed_seq);
  json.key("interrupted").value(status.interrupted);
  json.key("store_problems").begin_array();
  for (const std::string& problem : status.store_problems) json.value(problem);
  json.end_array();
  json.key("pending_commit").value(status.pending_commit);
  json.end_object();
  return line(json);
}

std::string format_show_response(const std::optional<store::CurrentCalibration>& current) {
  JsonWriter json;
  json.begin_object().key("ok").value(true).key("present").value(current.has_value());
  if (current) {
    const Calibration& c = current->calibration;
    json.key("seq").value(current->seq).key("created").value(c.created).key("robot").value(c.robot);
    json.key("model").begin_array();
    for (const std::string& term : c.model) json.value(term);
    json.end_array();
    json.key("samples").value(c.samples);
    json.key("winches").begin_array();
    for (const WinchCalibration& w : c.winches) {
      json.begin_object();
      vector3(json.key("anchor"), w.anchor_world);
      vector3(json.key("anchor_sigma"), w.anchor_sigma);
      json.key("offset").value(w.offset_m).key("offset_sigma").value(w.offset_sigma_m);
      json.end_object();
    }
    json.end_array();
    json.key("fit").begin_object();
    json.key("cost_initial").value(c.fit.cost_initial).key("cost_final").value(c.fit.cost_final);
    json.key("iterations").value(c.fit.iterations);
    json.key("rms_encoder").value(c.fit.rms_encoder_m).key("rms_force").value(c.fit.rms_force_n);
    json.end_object();
  }
  json.end_object();
  return line(json);
}

std::string format_history_response(const std::vector<store::HistoryEntry>& history) {
  JsonWriter json;
  json.begin_object().key("ok").value(true).key("history").begin_array();
  for (const store::HistoryEntry& entry : history) {
    json.begin_object();
    json.key("seq").value(entry.seq).key("current").value(entry.current).key("valid").value(entry.valid);
    json.key("created").value(entry.created).key("robot").value(entry.robot).key("samples").value(entry.samples);
    json.key("problem").value(entry.problem);
    json.end_object();
  }
  json.end_array().end_object();
  return line(json);
}

}  // namespace cdpr::control
