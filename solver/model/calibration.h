#pragma once
// What calibration produces (calibration.toml) and what a simulator knows
// (truth.toml), docs/FORMATS.md. Plain value types.

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/model/robot.h"

namespace cdpr {

struct WinchCalibration {
  Eigen::Vector3d anchor_world = Eigen::Vector3d::Zero();  // [m] estimated pulley exit point
  Eigen::Vector3d anchor_sigma = Eigen::Vector3d::Zero();  // [m] 1-sigma per axis
  double offset_m = 0.0;                                   // [m] encoder offset
  double offset_sigma_m = 0.0;                             // [m] 1-sigma
};

struct FitSummary {
  double cost_initial = 0.0;
  double cost_final = 0.0;
  int iterations = 0;
  double rms_encoder_m = 0.0;
  double rms_force_n = 0.0;
};

// One sensor reading of one samples.csv row: a reading a calibration
// rejected as a gross error (residual in sigmas), or one a simulator made
// wrong on purpose (error in the sensor's unit: m or N).
enum class SensorKind { kEncoder, kForce };
struct SensorReading {
  int row = 0;        // sample id (samples.csv `id`)
  SensorKind sensor = SensorKind::kEncoder;
  int cable = 0;      // encoder: its cable; force: the reference cable
  double value = 0.0; // rejected: normalised residual [sigma]; planted: error [m or N]
  // rejected: 0 when the reading was named alone; otherwise the readings of
  // its row with the same group number are one suspect group: the row holds
  // a gross error the data cannot pin on one of them, so all were left out.
  int group = 0;
};
inline const char* sensor_name(SensorKind kind) { return kind == SensorKind::kEncoder ? "encoder" : "force"; }

// Fitted parameters of extra model terms, by name (docs/FORMATS.md [effects]);
// scalars hold one value, per-cable terms one value per cable.
using EffectValues = std::map<std::string, std::vector<double>>;

// How the daemon's run behind a fit went (calibration.toml [run]); offline
// fits have none.
struct RunSummary {
  double robot_time_s = 0.0;  // from the run's start to the fit's acceptance [s]
  int waypoints = 0;          // visited: sampled or skipped
  std::string strategy;       // "spread", "informative" or "sequential"
  std::string stop;           // why the waypoints ended ("plan done", "target reached", ...)
};

struct Calibration {
  int format = 1;
  std::string created;  // RFC 3339 UTC, e.g. 2026-11-22T10:15:00Z
  std::string robot;
  std::vector<std::string> model{"catenary"};
  int samples = 0;
  std::vector<WinchCalibration> winches;
  FitSummary fit;
  EffectValues effects;
  // Readings refused as gross errors, left out of the final fit (with the
  // rigid model their whole rows, which `samples` then does not count).
  std::vector<SensorReading> rejected;
  // Empty when the model fits the data; otherwise why not, in words with
  // the evidence (chi-square of the residuals against the noise, or an
  // under-determined problem). Sigmas are already scaled up by the misfit.
  std::string model_warning;
  std::optional<RunSummary> run;
};

struct WinchTruth {
  Eigen::Vector3d anchor_world = Eigen::Vector3d::Zero();
  double offset_m = 0.0;
};

struct Truth {
  std::vector<WinchTruth> winches;
  EffectValues effects;
  // [effects] keys whose value is not a number or a list of numbers (e.g.
  // `massless = true`): kept by name, never compared.
  std::vector<std::string> uncompared_effects;
  std::vector<SensorReading> outliers;  // readings the simulator made wrong on purpose
};

}  // namespace cdpr
