#pragma once
// Which reading of a row is the gross error. A robust fit can spread one
// gross encoder error over its row: the row's own pose and reference force
// move (a Cauchy loss makes two moderate residuals cheaper than one large
// one), so the largest residual may sit on the load cell or another cable.
// Leave-one-out decides instead: the row's pose and force are refitted
// (Levenberg-Marquardt, everything global held) without each of its readings in
// turn; the reading whose removal leaves the smallest chi-square of the
// rest, and leaves it explained (no reading beyond the threshold, the
// chi-square within the threshold squared), is the gross error. When no
// single reading explains the row, each pair is tried (a row may hold two
// gross errors, e.g. a slipped cable and a load-cell spike, and the single
// removal that looks best may be neither), and beyond a pair one reading
// more per round while the rest is not explained. When another choice
// explains the rest nearly as well (its chi-square within the chi-square(1)
// quantile at 1e-3, 10.83, of the best), the data cannot tell which is
// wrong: readings in every such choice are named alone, the others as one
// suspect group (SensorReading::group), all left out. Each reading left out
// carries its residual in the refit without all of them: its prediction
// minus the reading.

#include <span>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "solver/model/calibration.h"
#include "solver/nls/problem.h"

namespace cdpr {

// One reading of a row: its factor in the problem, the residual row in it.
struct RowReading {
  int factor = 0;
  int residual_row = 0;
  SensorKind sensor = SensorKind::kEncoder;
  int cable = 0;
  double spread = 1.0;  // robust spread of its kind (solver/calibration/gross_errors.h)
};

// `row_factors`: every factor of the row (pose prior and readings), whose
// variables are the row's pose (PoseKey), optionally its ReferenceForceKey,
// and global ones held at their values in `problem`. Factors are evaluated
// as they are (their loss must be least squares while this runs).
std::vector<SensorReading> attribute_row(const Problem& problem, int row_id, int pose_index,
                                         const std::vector<int>& row_factors, const std::vector<RowReading>& readings,
                                         double threshold_sigma);

// The readings a final catenary fit kept that look like gross errors once
// studentised within their row: the whitened residual r over sqrt(1 - h),
// h its leverage in the fit of the row's own pose and reference force (its
// readings, height rows and pose prior; every global held). r^2 / (1 - h)
// is, to first order, the chi-square drop when the reading is left out and
// the row refitted: the likelihood-ratio statistic of "this reading is a
// gross error". The residual alone understates it where the row's pose
// takes most of an error: a load cell whose row's orientation absorbs
// 86 N (17 sigma) keeps a residual of 2 sigma, while leaving it out lowers
// the chi-square by 38. Holding the globals makes it an upper bound of the
// drop a full refit gives. Returned: each reading whose studentised
// residual (its value) exceeds bar_sigma and whose statistic exceeds every
// other reading's of its row by more than 10.83 (the data tell it from
// them, as in attribute_row), worst first. Readings the row's unknowns
// carry entirely (h within 1e-9 of 1) are not tested. Empty when the fit
// failed or is rigid. Rows whose FittedRow::largest_studentised is below
// bar_sigma by a margin are not evaluated again.
std::vector<SensorReading> hidden_gross_errors(const Robot& robot, const CalibrationOptions& options,
                                               const CalibrationResult& result, double bar_sigma);

// The largest studentised residual among `sample`'s kept readings, as
// hidden_gross_errors computes it, from the whitened residuals and Jacobian
// blocks a solver evaluated at the fit (after the loss hidden_gross_errors
// uses): the row's reading factor's residuals and its pose and reference
// force blocks, the pose prior's pose block, each row-major. Infinity when
// it cannot be told safely (blocks of other sizes, a singular row, a
// reading the row's unknowns carry almost entirely).
double largest_studentised_residual(const Sample& sample, std::span<const double> residual,
                                    std::span<const double> pose_jacobian, std::span<const double> force_jacobian,
                                    std::span<const double> prior_jacobian);

}  // namespace cdpr
