#include "src/formats/format_error.h"

namespace cdpr {

std::string FormatError::message() const {
  std::string text = file;
  if (line > 0) text += ":" + std::to_string(line);
  text += ": ";
  if (!field.empty()) text += field + ": ";
  return text + reason;
}

}  // namespace cdpr
