#include "src/formats/calibration_toml.h"

#include <cstdio>
#include <cstdlib>

#include "src/formats/effects_toml.h"
#include "src/formats/sensor_readings_toml.h"
#include "src/formats/toml_reader.h"
#include "src/formats/toml_writer.h"

namespace cdpr::formats {
namespace {

constexpr Presence kRequired = Presence::kRequired;
constexpr Presence kOptional = Presence::kOptional;

// The calibration.toml layout this code reads and writes. A reader of a
// newer file must not guess at keys it does not know, so other versions are
// refused before anything else is looked at.
constexpr std::int64_t kFormatVersion = 1;

std::vector<WinchCalibration> read_winches(TomlReader& reader, const toml::table& root) {
  std::vector<WinchCalibration> winches;
  for (const toml::table* table : reader.tables(root, "winch", "")) {
    const std::string path = "winch[" + std::to_string(winches.size()) + "]";
    reader.check_keys(
        *table, path,
        {{"anchor", kRequired}, {"anchor_sigma", kRequired}, {"offset", kRequired}, {"offset_sigma", kRequired}});
    WinchCalibration& winch = winches.emplace_back();
    winch.anchor_world = reader.vector3(*table, "anchor", path);
    winch.anchor_sigma = reader.vector3(*table, "anchor_sigma", path, Bound::kNonNegative);
    winch.offset_m = reader.number(*table, "offset", path);
    winch.offset_sigma_m = reader.number(*table, "offset_sigma", path, Bound::kNonNegative);
  }
  return winches;
}

FitSummary read_fit(TomlReader& reader, const toml::table& root) {
  const toml::table& table = reader.table(root, "fit", "");
  reader.check_keys(table, "fit",
                    {{"cost_initial", kRequired},
                     {"cost_final", kRequired},
                     {"iterations", kRequired},
                     {"rms_encoder", kRequired},
                     {"rms_force", kRequired}});
  FitSummary fit;
  fit.cost_initial = reader.number(table, "cost_initial", "fit", Bound::kNonNegative);
  fit.cost_final = reader.number(table, "cost_final", "fit", Bound::kNonNegative);
  fit.iterations = reader.count(table, "iterations", "fit");
  fit.rms_encoder_m = reader.number(table, "rms_encoder", "fit", Bound::kNonNegative);
  fit.rms_force_n = reader.number(table, "rms_force", "fit", Bound::kNonNegative);
  return fit;
}

// [run]: written by the daemon; offline fits and older files have none.
std::optional<RunSummary> read_run(TomlReader& reader, const toml::table& root) {
  if (!root.contains("run")) return std::nullopt;
  const toml::table& table = reader.table(root, "run", "");
  reader.check_keys(table, "run",
                    {{"robot_time", kRequired}, {"waypoints", kRequired}, {"strategy", kRequired}, {"stop", kRequired}});
  RunSummary run;
  run.robot_time_s = reader.number(table, "robot_time", "run", Bound::kNonNegative);
  run.waypoints = reader.count(table, "waypoints", "run");
  run.strategy = reader.string(table, "strategy", "run");
  run.stop = reader.string(table, "stop", "run");
  return run;
}

Calibration read_calibration(TomlReader& reader, const toml::table& root) {
  Calibration calibration;

  const std::int64_t format = reader.integer(root, "format", "");
  if (!reader.failed() && format != kFormatVersion) {
    reader.fail(TomlReader::line_of(*root.get("format")), "format",
                "unsupported format version " + std::to_string(format) + "; this build reads version " +
                    std::to_string(kFormatVersion));
  }
  reader.check_keys(root, "",
                    {{"format", kRequired},
                     {"created", kRequired},
                     {"robot", kRequired},
                     {"model", kRequired},
                     {"samples", kRequired},
                     {"winch", kRequired},
                     {"fit", kRequired},
                     {"effects", kOptional},
                     {"model_warning", kOptional},
                     {"rejected", kOptional},
                     {"run", kOptional}});
  calibration.format = static_cast<int>(format);
  calibration.created = reader.offset_date_time(root, "created", "");
  calibration.robot = reader.string(root, "robot", "");
  calibration.model = reader.strings(root, "model", "");
  calibration.samples = reader.count(root, "samples", "");
  if (root.contains("model_warning")) calibration.model_warning = reader.string(root, "model_warning", "");
  calibration.winches = read_winches(reader, root);
  calibration.fit = read_fit(reader, root);
  calibration.effects = read_effects(reader, root);
  calibration.rejected = read_sensor_readings(reader, root, "rejected", "residual");
  calibration.run = read_run(reader, root);
  return calibration;
}

}  // namespace

Expected<Calibration, FormatError> parse_calibration_toml(std::string_view text, const std::string& source) {
  return parse_toml<Calibration>(text, source, read_calibration);
}

Expected<Calibration, FormatError> read_calibration_toml(const std::string& path) {
  return parse_file(path, parse_calibration_toml);
}

std::string format_calibration_toml(const Calibration& calibration) {
  // `created` is written bare (a TOML date-time); anything else would make a
  // file that no reader accepts, so it is a broken invariant of the caller.
  if (!is_offset_date_time(calibration.created)) {
    std::fprintf(stderr, "format_calibration_toml: created '%s' is not an RFC 3339 date-time with zone\n",
                 calibration.created.c_str());
    std::abort();
  }
  std::string out;
  append_line(out, "format = " + std::to_string(kFormatVersion));
  append_line(out, "created = " + calibration.created);
  append_line(out, "robot = " + toml_string(calibration.robot));
  append_line(out, "model = " + toml_strings(calibration.model), "the model terms that were fitted");
  append_line(out, "samples = " + std::to_string(calibration.samples), "rows fitted");
  if (!calibration.model_warning.empty()) {
    append_line(out, "model_warning = " + toml_string(calibration.model_warning),
                "why the model is not trusted (docs/FORMATS.md)");
  }

  for (std::size_t i = 0; i < calibration.winches.size(); ++i) {
    const WinchCalibration& winch = calibration.winches[i];
    out += '\n';
    append_line(out, "[[winch]]", "cable " + std::to_string(i));
    append_line(out, "anchor = " + toml_vector3(winch.anchor_world), "m, world frame (estimated)");
    append_line(out, "anchor_sigma = " + toml_vector3(winch.anchor_sigma), "m, 1-sigma from the fit's covariance");
    append_line(out, "offset = " + toml_number(winch.offset_m), "m");
    append_line(out, "offset_sigma = " + toml_number(winch.offset_sigma_m), "m");
  }

  const FitSummary& fit = calibration.fit;
  out += "\n[fit]\n";
  append_line(out, "cost_initial = " + toml_number(fit.cost_initial));
  append_line(out, "cost_final = " + toml_number(fit.cost_final));
  append_line(out, "iterations = " + std::to_string(fit.iterations));
  append_line(out, "rms_encoder = " + toml_number(fit.rms_encoder_m), "m");
  append_line(out, "rms_force = " + toml_number(fit.rms_force_n), "N");

  append_effects(out, calibration.effects);
  append_sensor_readings(out, calibration.rejected, "rejected", "residual",
                         "normalised residual [sigma] at the robust fit; left out of the final fit");
  if (const std::optional<RunSummary>& run = calibration.run) {
    out += "\n[run]\n";
    append_line(out, "robot_time = " + toml_number(run->robot_time_s), "s, from the run's start to the fit");
    append_line(out, "waypoints = " + std::to_string(run->waypoints), "visited: sampled or skipped");
    append_line(out, "strategy = " + toml_string(run->strategy));
    append_line(out, "stop = " + toml_string(run->stop), "why the waypoints ended");
  }
  return out;
}

}  // namespace cdpr::formats
