#pragma once
// Human-readable progress and summaries of a calibration, shared by the
// offline tool and anything else that prints a fit.

#include <cstdio>
#include <string>

#include "solver/calibrate.h"

namespace cdpr::tools {

void print_iteration(std::FILE* out, const IterationSummary& it);
void print_summary(std::FILE* out, const CalibrationResult& result, const Robot& robot);
// Fitted (or true) [effects] values, each with its "<name>_sigma" if present.
void print_effects(std::FILE* out, const EffectValues& effects);
// Anchor and offset errors against a simulator's truth.toml.
void print_truth_comparison(std::FILE* out, const Calibration& calibration, const Truth& truth);
// The current UTC time in the RFC 3339 form calibration.toml uses.
std::string utc_timestamp_now();

}  // namespace cdpr::tools
