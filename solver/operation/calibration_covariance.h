#pragma once
// The joint covariance of a calibration's anchors and offsets, recovered
// from the samples it was fitted on (calibration.toml keeps per-axis sigmas
// only). Along each cable the fit knows the length far better than the
// anchor and the offset apart, so their errors are strongly correlated;
// the pose from the cables with per-variable priors overstates its own
// uncertainty several times (docs/operation.md).
//
// The fit is the calibration's graph (each sample's kineto-static factor and
// measured pose, anchors and offsets free, model terms held at their
// values) linearised where Levenberg-Marquardt ends from the committed
// values; scaled up, like the calibration's sigmas, where those are larger.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "solver/model/calibration.h"
#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr {

// Order: anchor 0 (x y z) .. anchor 3, then offset 0 .. offset 3.
inline constexpr int kCalibrationDimension = 4 * kCableCount;
using CalibrationCovariance = Eigen::Matrix<double, kCalibrationDimension, kCalibrationDimension>;

// Empty with *why when the samples cannot carry the fit (none, without a
// measured pose, not evaluable) or the covariance is singular.
std::optional<CalibrationCovariance> calibration_covariance(const Robot& robot, const Calibration& calibration,
                                                            const std::vector<Sample>& samples,
                                                            double height_sigma_m, std::string* why);

}  // namespace cdpr
