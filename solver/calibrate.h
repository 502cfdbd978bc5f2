#pragma once
// One calibration from measured static poses: build the factor graph of the
// paper (Sec. IV) from nominal anchors and the data alone, solve it, and
// extract anchors and offsets with their 1-sigma from the covariance.
// Pure numerics: no I/O, no clock; progress is reported through a callback.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "solver/calibration.h"
#include "solver/effects.h"
#include "solver/levenberg_marquardt.h"
#include "solver/problem.h"
#include "solver/robot.h"
#include "solver/sample.h"

namespace cdpr {

enum class CableModelKind { kRigid, kCatenary };

struct CalibrationOptions {
  CableModelKind cable_model = CableModelKind::kCatenary;
  double huber_width = 0.0;  // robust loss width in sigma units; <= 0: none
  // Well-determined fits take 10-60; a few with sparse data (8 poses on the
  // small robot) crawl along a flat valley for 250-450 before converging,
  // and stopping them at 200 left them up to 0.3 m short even on noiseless data.
  int max_iterations = 1000;
  // Sigma [m] of the attachment-height consistency of Eq. (15): a model
  // identity, not a sensor, so it is held much tighter than the pose noise.
  double height_sigma_m = 1e-2;
  // Model terms fitted on top of the catenary (solver/effects.h), each with
  // its own EffectKey variable started at 0 ("absent"); catenary only.
  std::vector<Effect> effects;
  std::function<void(const IterationSummary&)> progress;  // may be empty
};

// One fitted model term in the solver's parameter units (solver/effects.h).
struct FittedEffect {
  Effect effect = Effect::kElasticity;
  std::vector<double> value;
  std::vector<double> sigma;  // 1-sigma from the covariance
};

struct CalibrationResult {
  bool ok = false;
  std::string message;      // why it failed, or the solver's termination message
  Calibration calibration;  // filled when ok (created/robot left to the caller)
  SolverSummary solver;
  std::vector<int> rejected_samples;  // sample ids refused before the solve, with reasons in message
  std::vector<FittedEffect> effects;  // in CalibrationOptions::effects order, when ok
  // Covariance (tangent) of the global variables, in global_keys order:
  // AnchorKey(i), OffsetKey(i) per cable, then each effect's EffectKey.
  std::vector<Key> global_keys;
  Eigen::MatrixXd global_covariance;
};

// The factor graph of one calibration at its data-driven start, for
// calibrate() and for benchmarks that must solve exactly the same problem.
struct BuiltProblem {
  std::unique_ptr<Problem> problem;   // null when the inputs were refused (see message)
  std::vector<Sample> samples;        // the samples in the problem, pose k = samples[k]
  std::vector<int> rejected_samples;  // ids the model could not be started from
  std::string message;
};
BuiltProblem build_calibration_problem(const Robot& robot, const std::vector<Sample>& samples,
                                       const CalibrationOptions& options);

CalibrationResult calibrate(const Robot& robot, const std::vector<Sample>& samples,
                            const CalibrationOptions& options);

}  // namespace cdpr
