#include "src/formats/run_log_toml.h"

#include "src/formats/text_file.h"
#include "src/formats/toml_reader.h"
#include "src/formats/toml_writer.h"

namespace cdpr::formats {
namespace {

constexpr int kFormatVersion = 1;

bool known_outcome(const std::string& outcome) {
  for (const char* known : {kRunRunning, kRunCommitted, kRunFailed, kRunAborted, kRunInterrupted}) {
    if (outcome == known) return true;
  }
  return false;
}

RunLog read_run_log(TomlReader& reader, const toml::table& root) {
  reader.check_keys(root, "",
                    {{"format", Presence::kRequired}, {"run", Presence::kRequired}, {"outcome", Presence::kRequired},
                     {"reason", Presence::kOptional}, {"robot", Presence::kRequired}, {"started", Presence::kRequired},
                     {"finished", Presence::kOptional}, {"robot_time_s", Presence::kRequired},
                     {"waypoints_planned", Presence::kRequired}, {"strategy", Presence::kOptional},
                     {"stop", Presence::kOptional}, {"samples", Presence::kRequired},
                     {"skipped", Presence::kRequired}, {"calibration", Presence::kOptional},
                     {"diagnosis", Presence::kOptional}, {"refit_of", Presence::kOptional},
                     {"extends", Presence::kOptional},
                     {"waypoint", Presence::kOptional},
                     {"fault", Presence::kOptional}});
  RunLog log;
  if (const auto format = reader.integer(root, "format", ""); !reader.failed() && format != kFormatVersion) {
    reader.fail(TomlReader::line_of(*root.get("format")), "format",
                "format " + std::to_string(format) + " is not known (this program reads " +
                    std::to_string(kFormatVersion) + ")");
  }
  log.run = reader.count(root, "run", "");
  log.outcome = reader.string(root, "outcome", "");
  if (!reader.failed() && !known_outcome(log.outcome)) {
    reader.fail(TomlReader::line_of(*root.get("outcome")), "outcome",
                "\"" + log.outcome + "\" is not running, committed, failed, aborted or interrupted");
  }
  if (root.contains("reason")) log.reason = reader.string(root, "reason", "");
  log.robot = reader.string(root, "robot", "");
  log.started = reader.string(root, "started", "");
  if (root.contains("finished")) log.finished = reader.string(root, "finished", "");
  log.robot_time_s = reader.number(root, "robot_time_s", "", Bound::kNonNegative);
  log.waypoints_planned = reader.count(root, "waypoints_planned", "");
  if (root.contains("strategy")) log.strategy = reader.string(root, "strategy", "");
  if (root.contains("stop")) log.stop = reader.string(root, "stop", "");
  log.samples = reader.count(root, "samples", "");
  log.skipped = reader.count(root, "skipped", "");
  if (root.contains("calibration")) log.calibration = reader.count(root, "calibration", "");
  if (root.contains("diagnosis")) log.diagnosis = reader.string(root, "diagnosis", "");
  if (root.contains("refit_of")) log.refit_of = reader.count(root, "refit_of", "");
  if (root.contains("extends")) log.extends = reader.count(root, "extends", "");
  // Absent arrays are empty: a run that ended before its first waypoint, a run without faults.
  const auto tables = [&](const char* key) {
    return root.contains(key) ? reader.tables(root, key, "") : std::vector<const toml::table*>{};
  };
  for (const toml::table* table : tables("waypoint")) {
    const std::string path = "waypoint[" + std::to_string(log.waypoints.size()) + "]";
    reader.check_keys(*table, path,
                      {{"index", Presence::kRequired}, {"outcome", Presence::kRequired}, {"at_s", Presence::kRequired},
                       {"sample", Presence::kOptional}, {"why", Presence::kOptional}});
    RunWaypoint& waypoint = log.waypoints.emplace_back();
    waypoint.index = reader.count(*table, "index", path);
    waypoint.outcome = reader.string(*table, "outcome", path);
    waypoint.at_s = reader.number(*table, "at_s", path, Bound::kNonNegative);
    if (table->contains("sample")) waypoint.sample = reader.count(*table, "sample", path);
    if (table->contains("why")) waypoint.why = reader.string(*table, "why", path);
  }
  for (const toml::table* table : tables("fault")) {
    const std::string path = "fault[" + std::to_string(log.faults.size()) + "]";
    reader.check_keys(*table, path, {{"at_s", Presence::kRequired}, {"text", Presence::kRequired}});
    RunFault& fault = log.faults.emplace_back();
    fault.at_s = reader.number(*table, "at_s", path, Bound::kNonNegative);
    fault.text = reader.string(*table, "text", path);
  }
  return log;
}

}  // namespace

std::string format_run_log_toml(const RunLog& log) {
  std::string out;
  append_line(out, "format = " + std::to_string(kFormatVersion), "run.toml format version");
  append_line(out, "run = " + std::to_string(log.run));
  append_line(out, "outcome = " + toml_string(log.outcome), "running, committed, failed, aborted, interrupted");
  append_line(out, "reason = " + toml_string(log.reason));
  append_line(out, "robot = " + toml_string(log.robot));
  append_line(out, "started = " + toml_string(log.started), "UTC");
  if (!log.finished.empty()) append_line(out, "finished = " + toml_string(log.finished), "UTC");
  append_line(out, "robot_time_s = " + toml_number(log.robot_time_s), "from the start to the end of the run");
  append_line(out, "waypoints_planned = " + std::to_string(log.waypoints_planned), "sequential: its max_count");
  if (!log.strategy.empty()) append_line(out, "strategy = " + toml_string(log.strategy));
  if (!log.stop.empty()) append_line(out, "stop = " + toml_string(log.stop), "why the waypoints ended");
  append_line(out, "samples = " + std::to_string(log.samples), "rows of samples.csv");
  append_line(out, "skipped = " + std::to_string(log.skipped), "waypoints without equilibrium");
  if (log.calibration > 0) append_line(out, "calibration = " + std::to_string(log.calibration), "history sequence number");
  if (!log.diagnosis.empty()) append_line(out, "diagnosis = " + toml_string(log.diagnosis));
  if (log.refit_of > 0) append_line(out, "refit_of = " + std::to_string(log.refit_of), "the run whose samples were refitted");
  if (log.extends > 0) append_line(out, "extends = " + std::to_string(log.extends), "samples.csv begins with this run's samples");
  for (const RunWaypoint& waypoint : log.waypoints) {
    out += '\n';
    append_line(out, "[[waypoint]]");
    append_line(out, "index = " + std::to_string(waypoint.index));
    append_line(out, "outcome = " + toml_string(waypoint.outcome));
    append_line(out, "at_s = " + toml_number(waypoint.at_s));
    if (waypoint.sample >= 0) append_line(out, "sample = " + std::to_string(waypoint.sample));
    if (!waypoint.why.empty()) append_line(out, "why = " + toml_string(waypoint.why));
  }
  for (const RunFault& fault : log.faults) {
    out += '\n';
    append_line(out, "[[fault]]");
    append_line(out, "at_s = " + toml_number(fault.at_s));
    append_line(out, "text = " + toml_string(fault.text));
  }
  return out;
}

Expected<RunLog, FormatError> parse_run_log_toml(std::string_view text, const std::string& source) {
  return parse_toml<RunLog>(text, source, read_run_log);
}

Expected<RunLog, FormatError> read_run_log_toml(const std::string& path) { return parse_file(path, parse_run_log_toml); }

}  // namespace cdpr::formats
