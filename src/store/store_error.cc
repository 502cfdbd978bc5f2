#include "src/store/store_error.h"

#include <cerrno>
#include <cstring>

namespace cdpr::store {

std::string StoreError::message() const {
  std::string text = operation + " " + path;
  if (errno_value != 0) text += std::string(": ") + std::strerror(errno_value);
  if (!reason.empty()) text += ": " + reason;
  return text;
}

StoreError errno_error(std::string operation, std::string path) {
  return StoreError{std::move(operation), std::move(path), errno, ""};
}

}  // namespace cdpr::store
