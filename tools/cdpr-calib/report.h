#pragma once
// Human-readable progress and summaries of a calibration, shared by the
// offline tool and anything else that prints a fit.

#include <cstdio>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"

namespace cdpr::tools {

void print_iteration(std::FILE* out, const IterationSummary& it);
void print_summary(std::FILE* out, const CalibrationResult& result, const Robot& robot);
// The stages calibrate() ran (CalibrationResult::stages), one line each,
// nested stages indented under the one that ran them.
void print_stages(std::FILE* out, const std::vector<CalibrationStage>& stages);
// Fitted (or true) [effects] values, each with its "<name>_sigma" if present.
void print_effects(std::FILE* out, const EffectValues& effects);
// Anchor and offset errors against a simulator's truth.toml; [effects] keys
// it cannot compare are named as not compared, never refused.
void print_truth_comparison(std::FILE* out, const Calibration& calibration, const Truth& truth);
// Readings rejected as gross errors: row, sensor, cable, residual in sigmas.
// One line: each model term the fit lacks, its score statistic / degrees of
// freedom and p, or that it is not identifiable (solver/calibration/term_tests.h).
void print_term_tests(std::FILE* out, const CalibrationResult& result);
void print_gross_errors(std::FILE* out, const std::vector<SensorReading>& rejected);
// One line: each sensor group's implied noise over robot.toml's sigma, and
// the groups whose residuals say they are noisier than stated.
void print_noise_scales(std::FILE* out, const std::vector<NoiseComponent>& noise);
// Each planted gross error of truth.toml and whether it was rejected.
void print_outlier_recall(std::FILE* out, const std::vector<SensorReading>& rejected,
                          const std::vector<SensorReading>& planted);
// The current UTC time in the RFC 3339 form calibration.toml uses.
std::string utc_timestamp_now();

}  // namespace cdpr::tools
