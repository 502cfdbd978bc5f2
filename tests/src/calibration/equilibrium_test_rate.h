#pragma once
// What the equilibrium detector's tests share: the pose source's rate.

#include "hal/clock.h"

namespace cdpr::calibration::test {

inline constexpr hal::TimeUs kPeriodUs = 20'000;  // 50 Hz observations

}  // namespace cdpr::calibration::test
