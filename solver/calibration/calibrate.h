#pragma once
// One calibration from measured static poses: build the factor graph of the
// paper (Sec. IV) from nominal anchors and the data alone, solve it, and
// extract anchors and offsets with their 1-sigma from the covariance.
// Pure numerics: no I/O, no clock; progress is reported through a callback.

#include <array>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/calibration/noise_scale.h"
#include "solver/model/calibration.h"
#include "solver/model/effects.h"
#include "solver/nls/levenberg_marquardt.h"
#include "solver/nls/loss.h"
#include "solver/nls/pose.h"
#include "solver/nls/problem.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr {

enum class CableModelKind { kRigid, kCatenary };

struct CalibrationOptions {
  CableModelKind cable_model = CableModelKind::kCatenary;
  // A Huber loss of this width [sigma] on the readings (and the pose prior)
  // of the final fit; <= 0: least squares. Gross errors are the robust
  // fit's business (below), not this.
  double huber_width = 0.0;
  // Robust fit (default): a Huber fit (convex, so it reaches the basin a
  // least-squares fit would from the same start while a few gross errors
  // pull only linearly), then, when a reading still stands out, a Cauchy fit
  // from there (redescending: a gross error's pull fades, graduated
  // non-convexity), then the test of solver/calibration/gross_errors.h on every reading;
  // the rows of rejected readings are left out and the fit is redone by
  // least squares. On clean data this ends at the least-squares minimum with
  // its covariance. false: least squares (or huber_width) alone.
  bool robust = true;
  double rejection_threshold_sigma = 5.0;  // normalised residual of a gross error
  // More rejected rows than this fraction and the calibration is refused:
  // the robot or its sensors need attention (or the model does not fit).
  double max_rejected_fraction = 0.4;
  // The model-fit test: the final fit's chi-square against its degrees of
  // freedom; a model that does not fit at this significance is reported in
  // Calibration::model_warning and its sigmas are scaled up by the misfit.
  double misfit_alpha = 1e-3;
  // The tests of the known model terms the fit does not have
  // (solver/calibration/term_tests.h): one score test per term at the final
  // fit, this level shared among them (Bonferroni). A term asked for is a
  // misfit as the chi-square test's is. <= 0, or misfit_alpha <= 0 (no
  // model-fit check at all): not run.
  double term_test_alpha = 1e-6;
  // Well-determined fits take 10-60; a few with sparse data (8 poses on the
  // small robot) crawl along a flat valley for 250-450 before converging,
  // and stopping them at 200 left them up to 0.3 m short even on noiseless data.
  int max_iterations = 1000;
  // Sigma [m] of the attachment-height consistency of Eq. (15): a model
  // identity, not a sensor, so it is held tight against the pose noise. For
  // rows weighted by robot.toml's noise; a row with its own sigmas scales it
  // down with its pose noise (solver/model/sample.h, row_height_sigma()).
  double height_sigma_m = 1e-2;
  // Model terms fitted on top of the catenary (solver/model/effects.h), each with
  // its own EffectKey variable started at 0 ("absent"); catenary only.
  std::vector<Effect> effects;
  std::function<void(const IterationSummary&)> progress;  // may be empty
};

// One fitted model term in the solver's parameter units (solver/model/effects.h).
struct FittedEffect {
  Effect effect = Effect::kElasticity;
  std::vector<double> value;
  std::vector<double> sigma;  // 1-sigma from the covariance
};

// The score test of one model term the final fit does not have
// (solver/calibration/term_tests.h).
struct TermTest {
  Effect effect = Effect::kElasticity;
  // False when its columns are (nearly) in the span of the fitted unknowns'
  // on these poses: the data cannot tell it apart, so it is not tested.
  bool identifiable = true;
  double statistic = 0.0;  // score statistic, ~ chi-square(dof) when the fitted model holds
  int dof = 0;             // directions of the term the data can see
  double p = 1.0;          // upper-tail probability of statistic
  bool asked_for = false;  // p below the per-term level
};

// A row's part of a fit's last linearisation (whitened, after the loss:
// LevenbergMarquardt::last_residuals, last_jacobian): its reading factor's
// residuals and Jacobian blocks of the pose, reference force, anchors and
// offsets (keys() order, each row-major, one after another), its pose
// prior's residuals and pose block.
struct FittedRowLinearization {
  static constexpr int kRows = 2 * kCableCount + 1;
  static constexpr int kColumns = 6 + 2 + 4 * kCableCount;
  static constexpr int kPriorRows = 6;
  std::array<double, kRows> residual{};
  std::array<double, kRows * kColumns> jacobian{};
  std::array<double, kPriorRows> prior_residual{};
  std::array<double, kPriorRows * 6> prior_jacobian{};
};

// One pose of the final fit as it ended: the row as fitted (gross errors
// masked), its platform pose and the reference cable's force (f_h, f_v).
struct FittedRow {
  Sample sample;
  Pose world_T_platform;
  Eigen::Vector2d reference_force = Eigen::Vector2d::Zero();
  // The largest studentised residual of its kept readings from the
  // solver's own last linearisation (largest_studentised_residual,
  // solver/calibration/row_attribution.h); infinity when not known.
  double largest_studentised = std::numeric_limits<double>::infinity();
  // Kept by a fit of the base catenary model (no model terms), for the
  // score test of missing terms (solver/calibration/term_tests.h); empty
  // otherwise.
  std::optional<FittedRowLinearization> linearization;
};

// Why a fit is flagged (CalibrationResult::misfit), the first that applies.
enum class MisfitCause {
  kNone,
  kUnderDetermined,  // fewer redundant rows than global unknowns
  kNotConverged,     // the solver stopped at its iteration limit
  kUnreached,        // residuals far beyond any missing term: the fit missed the readings
  kModel,            // the readings ask for a term the model lacks (chi-square or score test)
};

// What the user should do about a flagged fit, one sentence.
const char* misfit_advice(MisfitCause cause);

// Why calibrate() refused a fit whose rows have too many gross errors
// (solver/calibration/refusal_cause.h).
enum class Refusal {
  kNone,         // not refused: ok, or a fit that failed (message says why)
  kSensorFault,  // more rows with gross errors than allowed, and no model term or noise scale explains them
  kModelMisfit,  // as many rows, but a model term or a noise scale brings them within the limit
};

// One stage calibrate() ran (docs/calibration.md, "The stages of a
// calibration"), in the order they ran.
struct CalibrationStage {
  std::string name;       // e.g. "robust fit, Huber", "restart from a rigid fit's anchors"
  int depth = 0;          // 0: calibrate()'s own; n: inside the stage of depth n - 1 above it
  bool fallback = false;  // run because the stage before it failed or left the fit in doubt
  int iterations = 0;     // Levenberg-Marquardt iterations of its solves; 0 for a test
  double cost = std::numeric_limits<double>::quiet_NaN();  // its solve's final cost; NaN for a test
  std::string outcome;    // how it ended: the solver's stop, or what it decided and why
};

struct CalibrationResult {
  bool ok = false;
  std::string message;      // why it failed, or the solver's termination message
  Calibration calibration;  // filled when ok (created/robot left to the caller)
  SolverSummary solver;
  std::vector<int> rejected_samples;  // sample ids refused before the solve, with reasons in message
  // Gross errors found by the robust fit (also in calibration.rejected): its
  // rows were left out of the final fit. Filled when ok and when refused for
  // too many of them.
  std::vector<SensorReading> gross_errors;
  // When refused for its gross errors: the sensors or the model, with what
  // was tried (kModelMisfit: the candidate that explains the rows first).
  Refusal refusal = Refusal::kNone;
  std::string refusal_evidence;
  // Each reading left out of this fit (Sample::encoder_left_out,
  // force_left_out) as the fit predicts it: its normalised residual, its
  // row's pose and force fitted without it (a leave-one-out residual).
  std::vector<SensorReading> left_out_residuals;
  // The model-fit test of the final fit (when ok): chi-square, its degrees
  // of freedom and upper-tail probability; true when it failed or the
  // problem is under-determined (calibration.model_warning says which).
  double chi_square = 0.0;
  int degrees_of_freedom = 0;
  double misfit_probability = 1.0;
  bool misfit = false;
  // What the flag is about, for the advice that goes with it: only a model
  // that lacks a term is a case for cdpr-calib diagnose; a fit that stopped
  // short or an under-determined problem needs a better start or more poses.
  MisfitCause misfit_cause = MisfitCause::kNone;
  // The tests of the terms the model lacks, in kAllEffects order (when ok,
  // catenary and the model-fit check on); per-term level in term_test_level.
  std::vector<TermTest> term_tests;
  double term_test_level = 0.0;
  // The final catenary fit's rows, for the tests that follow it (when ok).
  std::vector<FittedRow> fitted_rows;
  std::vector<FittedEffect> effects;  // in CalibrationOptions::effects order, when ok
  // The noise the final fit's residuals imply per sensor group against
  // robot.toml's sigmas (solver/calibration/noise_components.h), when ok
  // (catenary): reported, not acted on; cdpr-calib diagnose weighs them.
  std::vector<NoiseComponent> noise;
  // Covariance (tangent) of the global variables, in global_keys order:
  // AnchorKey(i), OffsetKey(i) per cable, then each effect's EffectKey.
  std::vector<Key> global_keys;
  Eigen::MatrixXd global_covariance;
  // Every stage calibrate() ran on the way to this result, fallbacks and
  // checks included; the fits inside a search (row hypotheses, other
  // starts, swap test, hidden errors, refusal cause) are summed up in the
  // search's own stage.
  std::vector<CalibrationStage> stages;
};

// The factor graph of one calibration at its data-driven start, for
// calibrate() and for benchmarks that must solve exactly the same problem.
struct BuiltProblem {
  std::unique_ptr<Problem> problem;   // null when the inputs were refused (see message)
  // The loss of every reading row (solver/nls/loss.h's shared loss): set it
  // between solves; least squares (or the Huber of huber_width) when built.
  std::unique_ptr<LossFunction> reading_loss;
  // Per pose k: the factor holding its readings (catenary), or the first of
  // its kCableCount encoder factors (rigid), in problem->factors().
  std::vector<int> reading_factor;
  std::vector<Sample> samples;        // the samples in the problem, pose k = samples[k]
  std::vector<int> rejected_samples;  // ids the model could not be started from
  std::string message;
};
BuiltProblem build_calibration_problem(const Robot& robot, const std::vector<Sample>& samples,
                                       const CalibrationOptions& options);

// `samples` without the given gross errors: with the catenary model each
// rejected reading is left out of its row (Sample::encoder_left_out,
// force_left_out) and the rest of the row is kept; the rigid model has no
// per-reading mask, so the whole row goes.
std::vector<Sample> leave_out(const std::vector<Sample>& samples, const std::vector<SensorReading>& gross_errors,
                              CableModelKind cable_model);

// The robust fit (CalibrationOptions::robust), a restart with a looser
// height consistency when the first fit stops where the anchors are
// unobservable, the rows of gross errors left out and the fit redone, and
// the model-fit test. When that fit may not be at the minimum (it failed,
// left rows or readings out, or misfits), other starts are fitted too and
// the best fit kept (solver/calibration/start_selection.h), and on small
// sets the readings left out are checked against their row's and cable's
// other readings (docs/robust-calibration.md). Refuses (ok = false) when
// more than max_rejected_fraction of the rows have gross errors. The kept
// fit's missing model terms are tested last (term_tests).
CalibrationResult calibrate(const Robot& robot, const std::vector<Sample>& samples,
                            const CalibrationOptions& options);

}  // namespace cdpr
