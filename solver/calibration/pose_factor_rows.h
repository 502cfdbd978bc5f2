#pragma once
// The residual rows of a pose factor (solver/calibration/static_pose_factor.h,
// solver/calibration/effect_pose_factor.h) that are sensor readings: the encoders
// (Eq. 14) and the load cell (Eq. 16). The attachment-height rows between
// them (Eq. 15) are a model identity, not a reading.

#include <algorithm>
#include <array>

#include "solver/model/robot.h"
#include "solver/model/sample.h"

namespace cdpr {

constexpr int encoder_row(int cable) { return cable; }
inline constexpr int kForceRow = 2 * kCableCount;
inline constexpr std::array<int, kCableCount + 1> kReadingRows = {encoder_row(0), encoder_row(1), encoder_row(2),
                                                                  encoder_row(3), kForceRow};
static_assert(kCableCount == 4, "kReadingRows lists four encoder rows");

// The reading rows of a sample's pose factor that are left out (gross
// errors): their residuals and Jacobian rows are zero.
struct LeftOutRows {
  std::array<int, kCableCount + 1> rows{};
  int count = 0;
  bool contains(int row) const { return std::find(rows.begin(), rows.begin() + count, row) != rows.begin() + count; }
};
inline LeftOutRows left_out_rows(const Sample& sample) {
  LeftOutRows out;
  for (int i = 0; i < kCableCount; ++i) {
    if (sample.encoder_left_out[i]) out.rows[out.count++] = encoder_row(i);
  }
  if (sample.force_left_out) out.rows[out.count++] = kForceRow;
  return out;
}

}  // namespace cdpr
