#include "src/control/control_response.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "src/calibration/model_check_verdict.h"
#include "src/formats/number_text.h"
#include "src/report/sections.h"

namespace cdpr::control {
namespace {

// Members keep the order they are added in: the order is part of the
// protocol (clients and tests compare whole lines).
using Json = nlohmann::ordered_json;

// `value` as one line of JSON. Strings go through nlohmann (escaped, invalid
// UTF-8 replaced by U+FFFD, so no newline and no invalid text whatever a
// path or errno message holds). Floating-point numbers are written as the
// shortest text that reads back exactly (formats::shortest_text, as in the
// data files: 41 and 1e-04, where nlohmann writes 41.0 and 0.0001);
// non-finite ones as null.
void append_line_json(const Json& value, std::string& out) {
  switch (value.type()) {
    case Json::value_t::object: {
      out += '{';
      for (auto member = value.begin(); member != value.end(); ++member) {
        if (member != value.begin()) out += ',';
        append_line_json(Json(member.key()), out);
        out += ':';
        append_line_json(member.value(), out);
      }
      out += '}';
      return;
    }
    case Json::value_t::array: {
      out += '[';
      for (auto element = value.begin(); element != value.end(); ++element) {
        if (element != value.begin()) out += ',';
        append_line_json(*element, out);
      }
      out += ']';
      return;
    }
    case Json::value_t::number_float: {
      const double number = value.get<double>();
      out += std::isfinite(number) ? formats::shortest_text(number) : "null";
      return;
    }
    default: out += value.dump(-1, ' ', false, Json::error_handler_t::replace);
  }
}

std::string line(const Json& value) {
  std::string out;
  append_line_json(value, out);
  return out + "\n";
}

Json vector3(const Eigen::Vector3d& v) { return Json::array({v.x(), v.y(), v.z()}); }

Json string_array(const std::vector<std::string>& texts) {
  Json array = Json::array();
  for (const std::string& text : texts) array.push_back(text);
  return array;
}

// The last refit (refit_service.h); null before the first.
Json refit_json(const std::optional<RefitStatus>& refit) {
  if (!refit) return nullptr;
  Json json;
  json["run"] = refit->run;
  json["terms"] = refit->terms;
  json["state"] = refit->state;
  json["message"] = refit->message;
  json["committed_seq"] = refit->committed_seq;
  json["entry"] = refit->entry;
  return json;
}

// The run's waypoint strategy, its largest sigmas against their targets
// and the robot time still needed, for `calibctl status`.
void add_waypoint_progress(const calibration::CalibrationStatus& status, hal::TimeUs now_us, Json& json) {
  json["strategy"] = status.strategy;
  json["stop_reason"] = status.stop_reason;
  if (status.largest_anchor_sigma_m < 0.0) {
    json["sigma"] = nullptr;
  } else {
    Json sigma;
    sigma["anchor"] = status.largest_anchor_sigma_m;
    sigma["offset"] = status.largest_offset_sigma_m;
    sigma["target_anchor"] = status.target_anchor_sigma_m;
    sigma["target_offset"] = status.target_offset_sigma_m;
    json["sigma"] = std::move(sigma);
  }
  if (status.time_left_s < 0.0 || !calibration::is_running(status.state)) {
    json["time_left_s"] = nullptr;
  } else {
    const double since_s = 1e-6 * static_cast<double>(now_us - status.time_left_at_us);
    json["time_left_s"] = std::max(0.0, status.time_left_s - since_s);
  }
}

// "0x8130 (life guard or heartbeat error)"; "" for code 0.
std::string code_text(std::uint16_t code, const char* meaning) {
  if (code == 0) return {};
  char text[96];
  std::snprintf(text, sizeof(text), "0x%04X (%s)", static_cast<unsigned>(code), meaning);
  return text;
}

Json age_ms(hal::TimeUs age_us) { return age_us < 0 ? Json(nullptr) : Json(1e-3 * static_cast<double>(age_us)); }

Json nodes_json(const std::vector<calibration::CalibrationStatus::Node>& nodes) {
  Json array = Json::array();
  for (const auto& [winch, n] : nodes) {
    Json node;
    node["winch"] = winch;
    node["role"] = n.role;
    node["node_id"] = n.node_id;
    node["nmt"] = n.nmt;
    node["configured"] = n.configured;
    node["cia402"] = n.power_state;
    node["error_code"] = code_text(n.error_code, n.error_text);
    node["last_emcy"] = code_text(n.emcy_code, n.emcy_text);
    node["emcy_register"] = n.emcy_register;
    node["pdo_age_ms"] = age_ms(n.pdo_age_us);
    node["heartbeat_age_ms"] = age_ms(n.heartbeat_age_us);
    array.push_back(std::move(node));
  }
  return array;
}

}  // namespace

namespace {

Json operation_json(const operation::OperationStatus* operation, hal::TimeUs now_us) {
  if (operation == nullptr) return nullptr;
  const operation::OperationStatus& o = *operation;
  Json json;
  json["mode"] = "watch";
  json["state"] = o.state;
  json["calibration_seq"] = o.calibration_seq;
  json["rests"] = o.rests;
  json["localized"] = o.localized;
  json["detail"] = o.detail;
  json["last_problem"] = o.last_problem;
  if (!o.last) {
    json["last_rest"] = nullptr;
  } else {
    Json last;
    last["rest"] = o.last->rest;
    last["age_s"] = 1e-6 * static_cast<double>(now_us - o.last->seen_us);
    last["position"] = vector3(o.last->position_world);
    last["position_sigma"] = vector3(o.last->position_sigma_m);
    last["orientation_sigma"] = vector3(o.last->orientation_sigma_rad);
    last["onboard_sigmas"] = o.last->onboard_sigmas;
    json["last_rest"] = std::move(last);
  }
  if (!o.finding) {
    json["finding"] = nullptr;
  } else {
    const operation::FindingSummary& f = *o.finding;
    Json finding;
    finding["term"] = f.term;
    finding["meaning"] = f.meaning;
    finding["cable"] = f.cable;
    finding["value"] = f.value;
    finding["sigma"] = f.sigma;
    finding["since_rest"] = f.since_rest;
    finding["fired_at_rest"] = f.fired_at_rest;
    finding["fired_s_ago"] = 1e-6 * static_cast<double>(now_us - f.fired_us);
    finding["rests_fitted"] = f.rests_fitted;
    finding["calibration_fault"] = f.calibration_fault;
    finding["alike"] = string_array(f.alike);
    json["finding"] = std::move(finding);
  }
  json["refit"] = o.refit;
  return json;
}

}  // namespace

std::string format_status_response(const calibration::CalibrationStatus& status, hal::TimeUs now_us,
                                   const std::optional<RefitStatus>& refit,
                                   const operation::OperationStatus* operation) {
  Json json;
  json["ok"] = true;
  json["state"] = calibration::to_string(status.state);
  json["running"] = calibration::is_running(status.state);
  json["waypoint"] = status.waypoint;
  json["waypoints"] = status.waypoint_count;
  json["samples"] = status.samples;
  json["skipped"] = status.skipped;
  json["progress"] = status.progress;
  if (status.started_us < 0) {
    json["elapsed_s"] = nullptr;
  } else {
    const hal::TimeUs end_us = status.finished_us >= 0 ? status.finished_us : now_us;
    json["elapsed_s"] = 1e-6 * static_cast<double>(end_us - status.started_us);
  }
  add_waypoint_progress(status, now_us, json);
  json["reason"] = status.reason;
  json["note"] = status.note;
  json["detail"] = status.detail;
  json["device_faults"] = status.device_faults;
  json["committed_seq"] = status.committed_seq;
  json["interrupted"] = status.interrupted;
  json["store_problems"] = string_array(status.store_problems);
  json["pending_commit"] = status.pending_commit;
  if (status.run_outcome.empty()) {
    json["run"] = nullptr;
  } else {
    Json run;
    run["entry"] = status.run_entry;
    run["outcome"] = status.run_outcome;
    run["samples"] = status.samples;
    run["diagnosis"] = status.run_diagnosis;
    run["named_terms"] = string_array(calibration::model_check_terms(status.run_diagnosis));
    json["run"] = std::move(run);
  }
  json["refit"] = refit_json(refit);
  json["nodes"] = nodes_json(status.nodes);
  json["operation"] = operation_json(operation, now_us);
  return line(json);
}

std::string format_show_response(const std::optional<store::CurrentCalibration>& current,
                                 const std::optional<store::RunEntry>& run) {
  Json json;
  json["ok"] = true;
  json["present"] = current.has_value();
  if (current) {
    const Calibration& c = current->calibration;
    json["seq"] = current->seq;
    json["created"] = c.created;
    json["robot"] = c.robot;
    json["model"] = string_array(c.model);
    json["samples"] = c.samples;
    Json winches = Json::array();
    for (const WinchCalibration& w : c.winches) {
      Json winch;
      winch["anchor"] = vector3(w.anchor_world);
      winch["anchor_sigma"] = vector3(w.anchor_sigma);
      winch["offset"] = w.offset_m;
      winch["offset_sigma"] = w.offset_sigma_m;
      winches.push_back(std::move(winch));
    }
    json["winches"] = std::move(winches);
    Json fit;
    fit["cost_initial"] = c.fit.cost_initial;
    fit["cost_final"] = c.fit.cost_final;
    fit["iterations"] = c.fit.iterations;
    fit["rms_encoder"] = c.fit.rms_encoder_m;
    fit["rms_force"] = c.fit.rms_force_n;
    json["fit"] = std::move(fit);
    json["model_warning"] = c.model_warning;
    Json rejected = Json::array();
    for (const SensorReading& r : c.rejected) {
      Json reading;
      reading["row"] = r.row;
      reading["sensor"] = sensor_name(r.sensor);
      reading["cable"] = r.cable;
      reading["residual"] = r.value;
      // A suspect group of its row (calibration.toml [[rejected]]) and its members in words.
      if (r.group != 0) {
        reading["group"] = r.group;
        reading["group_members"] = report::suspect_group_text(c.rejected, r);
      }
      rejected.push_back(std::move(reading));
    }
    json["rejected"] = std::move(rejected);
    if (!run) {
      json["run"] = nullptr;
    } else {
      Json entry;
      entry["entry"] = run->path;
      entry["outcome"] = run->log.outcome;
      entry["samples"] = run->log.samples;
      entry["skipped"] = run->log.skipped;
      entry["robot_time_s"] = run->log.robot_time_s;
      entry["diagnosis"] = run->log.diagnosis;
      entry["named_terms"] = string_array(calibration::model_check_terms(run->log.diagnosis));
      // The report beside the calibration; null when the run has none (an older daemon's).
      const std::string report = run->path + "/" + store::RunHistory::kReportName;
      std::error_code error;
      if (std::filesystem::is_regular_file(report, error)) {
        entry["report"] = report;
      } else {
        entry["report"] = nullptr;
      }
      json["run"] = std::move(entry);
    }
  }
  return line(json);
}

std::string format_history_response(const std::vector<store::HistoryEntry>& history) {
  Json entries = Json::array();
  for (const store::HistoryEntry& entry : history) {
    Json item;
    item["seq"] = entry.seq;
    item["current"] = entry.current;
    item["valid"] = entry.valid;
    item["created"] = entry.created;
    item["robot"] = entry.robot;
    item["samples"] = entry.samples;
    item["problem"] = entry.problem;
    entries.push_back(std::move(item));
  }
  Json json;
  json["ok"] = true;
  json["history"] = std::move(entries);
  return line(json);
}

}  // namespace cdpr::control
