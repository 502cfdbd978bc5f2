#pragma once
// Numbers in operator messages ("tension 4.1 N below 20 N"): a few
// significant digits, not the round-trip precision of the data files.

#include <string>

namespace cdpr::calibration {

std::string significant(double value, int digits = 4);

}  // namespace cdpr::calibration
