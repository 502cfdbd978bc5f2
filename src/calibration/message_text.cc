#include "src/calibration/message_text.h"

#include <cstdio>

namespace cdpr::calibration {

std::string significant(double value, int digits) {
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", digits, value);
  return text;
}

}  // namespace cdpr::calibration
