#include "solver/calibration/refusal_cause.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "solver/calibration/noise_components.h"
#include "solver/calibration/single_fit.h"

namespace cdpr {
namespace {

// A pose-noise scale is tried when the least-squares fit of all rows
// implies at least this much: below it, a scale changes the weights too
// little to move a reading across the gross-error bar of 5 sigma.
constexpr double kMinNoiseScale = 1.5;

// The robust stage already measures the readings' own spread (encoder and
// load cell, solver/calibration/gross_errors.h), so only the groups it
// takes as stated get a scale here.
constexpr NoiseGroup kScaledGroups[] = {NoiseGroup::kPosition, NoiseGroup::kOrientation, NoiseGroup::kHeight};

struct Candidate {
  std::string name;
  Robot robot;
  std::vector<Sample> samples;
  CalibrationOptions options;
};

bool in_model(const CalibrationOptions& options, Effect e) {
  return std::find(options.effects.begin(), options.effects.end(), e) != options.effects.end();
}

std::string percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f %%", 100.0 * fraction);
  return text;
}

std::vector<Candidate> candidates_for(const Robot& robot, const std::vector<Sample>& samples,
                                      const CalibrationOptions& options, const CalibrationResult& refused) {
  CalibrationOptions quiet = options;
  quiet.progress = nullptr;
  std::vector<Candidate> out;
  if (options.cable_model == CableModelKind::kRigid) {
    CalibrationOptions catenary = quiet;
    catenary.cable_model = CableModelKind::kCatenary;
    out.push_back({"the catenary cable model (sagging cables)", robot, samples, catenary});
    return out;
  }
  for (Effect e : kAllEffects) {
    if (in_model(options, e)) continue;
    CalibrationOptions with = quiet;
    with.effects.push_back(e);
    if (!effect_set_conflict(with.effects).empty()) continue;
    out.push_back({std::string(effect_model_name(e)), robot, samples, with});
  }
  // The noise each pose group implies at a least-squares fit of the
  // readings the robust fit did not flag, from its anchors: with every
  // reading in, a pose group would take the gross errors' pull for noise
  // (a position noise of 37x explained 50 % rows with 0.5-2 m encoder
  // errors), while with them out a sensor fault leaves noise as stated and
  // a model misfit still shows where it does not fit.
  Robot start = robot;
  if (refused.calibration.winches.size() == static_cast<std::size_t>(kCableCount)) {
    for (int i = 0; i < kCableCount; ++i) start.winches[i].anchor_world = refused.calibration.winches[i].anchor_world;
  }
  CalibrationOptions plain = quiet;
  plain.robust = false;
  const CalibrationResult unflagged =
      calibrate_once(start, leave_out(samples, refused.gross_errors, options.cable_model), plain);
  for (const NoiseComponent& c : noise_components(start, plain, unflagged)) {
    if (std::find(std::begin(kScaledGroups), std::end(kScaledGroups), c.group) == std::end(kScaledGroups)) continue;
    if (!(c.scale >= kMinNoiseScale)) continue;
    Candidate noisier{"", robot, samples, quiet};
    scale_noise(c.group, c.scale, noisier.robot, noisier.samples, noisier.options);
    char name[96];
    std::snprintf(name, sizeof name, "%s %.1fx robot.toml", std::string(noise_group_description(c.group)).c_str(),
                  c.scale);
    noisier.name = name;
    out.push_back(std::move(noisier));
  }
  return out;
}

}  // namespace

double gross_error_row_fraction(const CalibrationResult& result, std::size_t rows) {
  std::vector<int> ids;
  for (const SensorReading& r : result.gross_errors) ids.push_back(r.row);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  return rows ? static_cast<double>(ids.size()) / static_cast<double>(rows) : 0.0;
}

void classify_refusal(const Robot& robot, const std::vector<Sample>& samples, const CalibrationOptions& options,
                      const RobustFit& fit, CalibrationResult& refused) {
  if (refused.refusal != Refusal::kSensorFault) return;
  const double before = gross_error_row_fraction(refused, samples.size());
  struct Outcome {
    const Candidate* candidate;
    bool explains;
    double fraction;  // of the rows with gross errors, 1 when the fit failed
    double per_dof;   // chi-square per degree of freedom of a kept fit
  };
  const std::vector<Candidate> candidates = candidates_for(robot, samples, options, refused);
  std::vector<Outcome> outcomes;
  for (const Candidate& c : candidates) {
    const CalibrationResult with = fit(c.robot, c.samples, c.options);
    // A fit that failed outright explains nothing; one refused again, or
    // kept, has its rows with gross errors.
    const bool fitted = with.ok || with.refusal != Refusal::kNone;
    const double fraction = fitted ? gross_error_row_fraction(with, samples.size()) : 1.0;
    const double per_dof = with.ok && with.degrees_of_freedom > 0 ? with.chi_square / with.degrees_of_freedom : 0.0;
    outcomes.push_back({&c, with.ok && fraction <= options.max_rejected_fraction, fraction, per_dof});
  }
  // Those that explain the rows first, the fewest rows left out and then the
  // better fit first: several often do (a weightless cable is a density
  // error, an encoder scale or a load-cell gain about equally), and each is
  // a lead for cdpr-calib diagnose, not the answer.
  std::stable_sort(outcomes.begin(), outcomes.end(), [](const Outcome& a, const Outcome& b) {
    if (a.explains != b.explains) return a.explains;
    if (!a.explains) return false;
    if (a.fraction != b.fraction) return a.fraction < b.fraction;
    return a.per_dof < b.per_dof;
  });
  std::string explaining, others;
  for (const Outcome& o : outcomes) {
    char text[64];
    if (o.explains) {
      std::snprintf(text, sizeof text, " (%s rows, chi2/dof %.1f)", percent(o.fraction).c_str(), o.per_dof);
      explaining += (explaining.empty() ? "" : ", ") + o.candidate->name + text;
    } else {
      others += (others.empty() ? "" : ", ") + o.candidate->name + " " + percent(o.fraction);
    }
  }
  if (!explaining.empty()) {
    refused.refusal = Refusal::kModelMisfit;
    refused.refusal_evidence = "the rows with gross errors (" + percent(before) + ") come within the limit with " +
                               explaining + (others.empty() ? "" : "; not with " + others);
  } else {
    refused.refusal_evidence = "no model term or pose-noise scale brings the rows with gross errors within the " +
                               percent(options.max_rejected_fraction) + " allowed (" +
                               (others.empty() ? std::string("none to try") : others) + ")";
  }
}

}  // namespace cdpr
