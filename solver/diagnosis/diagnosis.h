#pragma once
// The model-discrepancy workflow (docs/DESIGN.md "Model terms"): find where the
// model and the measurements disagree, name the missing effect (solver/
// effects.h), add it, and show the gap shrink on poses the fit never saw.
//
// Held-out misfit: by k-fold cross-validation, each fold's poses are
// predicted by a fit without them (solver/diagnosis/held_out.h), pooled over folds.
// Its chi-square is a predictive log-likelihood: a term that only fits
// training noise makes it worse, not better.
//
// Forward steps (model_search.h): every effect not yet in the model is
// tried. It is significant when its held-out chi2 drops, over the poses both
// models evaluate (held_out_comparison.h), and the likelihood ratio of the
// two fits on all samples (fit_comparison.h) is below alpha / m (Bonferroni
// over the m candidates of the round). The paired t of the per-pose held-out
// drops is reported, not tested: each drop's noise is twice its signal, so
// it has about half the likelihood ratio's z and would leave clear effects
// unnamed. Significant candidates are ranked by Akaike's criterion on all
// samples (by the held-out drop, a mimic with a tied drop can win over the
// true term); one whose fit leaves its physical range
// (effect_domain_violation) is rejected: it mimics something else. A round
// with significant candidates also tries pairs of them (pair_search.h), as
// one effect can mimic two others together. Adding a
// wider effect replaces the narrower one it contains (load_cell replaces
// load_cell_bias).
//
// Backward steps, once nothing more is significant: an added term not
// significant (alpha, likelihood ratio on all samples) with the rest of the
// model is removed, the least needed first; a wider term whose extra
// parameters are not significant at a round's level (alpha / m) goes back to
// its narrower form.
//
// Beside the terms, each round weighs one noise scale per sensor group
// (solver/calibration/noise_components.h: the variance components at the
// current fit): a group noisier than robot.toml states is a finding too,
// ranked with the terms by Akaike's criterion; taken, its sigma is scaled
// for every later fit. Candidates within kMimicAicMargin of the one a step
// takes form its mimic set: the data cannot tell them apart.
//
// Finally it says whether the held-out misfit is still above the noise:
// structure that no known effect explains. Pure numerics: progress goes
// through a callback.

#include <optional>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/calibration/chi_square.h"
#include "solver/diagnosis/diagnosis_options.h"
#include "solver/diagnosis/held_out.h"

namespace cdpr {

struct CandidateScore {
  Effect effect = Effect::kElasticity;
  // A noise candidate instead of a term: the sensor group whose stated sigma
  // the data say is too small, by this factor (variance components at the
  // current fit, solver/calibration/noise_components.h). Its fit_chi2_drop
  // is the -2 log-likelihood drop of the scaled sigma, its parameter one; it
  // has no held-out drop (one scale over hundreds of rows does not overfit).
  std::optional<NoiseGroup> noise;
  double noise_scale = 1.0;
  bool evaluated = false;      // fitted and evaluated on the held-out poses and on all samples
  std::string failure;         // why not, when !evaluated
  double held_out_chi2 = 0.0;
  double held_out_drop = 0.0;  // chi2 of the current model minus chi2 with this effect, on the poses both evaluate
  double t_statistic = 0.0;    // paired: mean per-pose held-out drop over its standard error (for the report)
  double fit_chi2_drop = 0.0;  // on all samples (solver/diagnosis/fit_comparison.h)
  double fit_p_value = 1.0;    // of the likelihood ratio
  int added_parameters = 0;    // of the fit on all samples over the current model's
  // Akaike's information criterion gain on all samples, fit_chi2_drop - 2 added_parameters:
  // ranks the significant candidates.
  double aic_gain() const { return fit_chi2_drop - 2.0 * added_parameters; }
  double level = 0.0;          // significant: fit_p_value below this and held_out_drop above 0
  bool significant = false;
};

struct DiagnosisStep {
  std::vector<Effect> model;  // effects in the model at this step
  Effect added = Effect::kElasticity;  // the effect this step added (not for step 0), or removed

  CalibrationResult fit;       // on all samples: the values reported for this model
  HeldOutEvaluation held_out;  // pooled over the folds, each fold predicted by a fit without it
  std::vector<CandidateScore> candidates;  // tried from this step, best first
  std::optional<Effect> replaced;  // the effect `added` took the place of (load_cell <-> load_cell_bias)
  bool removed = false;            // this step removed `added` from the model
  // A noise step: it scaled this group's stated sigma by noise_scale (for
  // this and every later step) and left the model as it was; `added` means
  // nothing then.
  std::optional<NoiseGroup> noise;
  double noise_scale = 1.0;
};

// One candidate of a mimic set: a term (or noise scale) that explains the
// data about as well as the one the step took.
struct MimicMember {
  Effect effect = Effect::kElasticity;
  std::optional<NoiseGroup> noise;  // a noise scale instead of a term
  double noise_scale = 1.0;
  double aic_gap = 0.0;   // Akaike gain of the term taken less this one's (>= 0)
  EffectValues values;    // its fitted [effects] values with their sigmas (terms)
  // What this member says the robot is: its model's whole fit on all
  // samples (anchors, offsets, effects); for a noise scale the fit of the
  // model it would have scaled, whose predictions it leaves as they are.
  // Where two members' predictions differ most is where a pose tells them
  // apart (tools/cdpr-calib/discriminating_poses.h).
  Calibration fit;
};

// Terms that explain the data about equally on these poses: the one a step
// took (members[0], gap 0) and every other candidate of its round whose
// Akaike gain is within kMimicAicMargin of it. The data cannot tell them
// apart; the step had to take one to go on.
inline constexpr double kMimicAicMargin = 4.0;
struct MimicSet {
  std::size_t step = 0;  // the step that took members[0]
  std::vector<MimicMember> members;
};

// A sensor group diagnose found noisier than robot.toml states, with the
// factor its sigma was scaled by.
struct NoiseFinding {
  NoiseGroup group = NoiseGroup::kEncoder;
  double scale = 1.0;
};

struct Diagnosis {
  bool ok = false;
  std::string message;  // why the workflow could not run
  int sample_count = 0;
  int folds = 0;
  std::vector<DiagnosisStep> steps;  // steps[0] is the starting model
  bool structure_remains = false;
  // Of the final held-out chi2 against its expected value; structure remains
  // when it is below alpha, however small the excess (its size is the final
  // step's normalized rms).
  double structure_p_value = 1.0;
  CalibrationResult final_fit;       // the final model on all samples (== steps.back().fit)
  std::vector<NoiseFinding> noise;   // the noise steps' findings, in step order
  std::vector<MimicSet> mimic_sets;  // the steps whose choice had mimics, in step order
  // Gross errors found by the robust fit of the starting model: left out of
  // the whole workflow (a handful of gross errors is not an effect), and
  // every fit after it is least squares on the same readings.
  std::vector<SensorReading> gross_errors;
};

// The mimic sets that still hold a term of the final model (or a noise
// finding): a set whose member was later removed says nothing of the answer.
std::vector<const MimicSet*> standing_mimic_sets(const Diagnosis& diagnosis);

// With options.fit.robust (the default) the starting model is first fitted
// robustly on all samples and its gross errors are left out (calibrate.h leave_out).
Diagnosis diagnose(const Robot& robot, const std::vector<Sample>& samples, const DiagnosisOptions& options);

}  // namespace cdpr
