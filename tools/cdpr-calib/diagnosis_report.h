#pragma once
// The report of `cdpr-calib diagnose`: plain text (also printed) and an HTML
// page with inline SVG residual plots of the held-out poses before (the
// starting model) and after (the final model).

#include <optional>
#include <string>

#include "solver/model/calibration.h"
#include "solver/diagnosis/diagnosis.h"

namespace cdpr::tools {

struct ReportContext {
  std::string robot_name;
  NoiseSigmas noise;
  std::optional<Truth> truth;  // simulated data: anchor errors and true effect values
  const Robot* nominal = nullptr;  // robot.toml: anchors moved, normalised residuals, anchor plots
};

std::string diagnosis_text(const Diagnosis& diagnosis, const ReportContext& context);
std::string diagnosis_html(const Diagnosis& diagnosis, const ReportContext& context);

// A mimic member's name: the term's, or "orientation noise x2.31".
std::string mimic_member_name(const MimicMember& member);

}  // namespace cdpr::tools
