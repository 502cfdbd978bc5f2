#pragma once
// Why a persistent-store operation failed: the operation, the path it
// touched and the operating system's reason (errno), or a content reason
// (e.g. the current calibration does not parse).

#include <string>

#include "src/formats/expected.h"

namespace cdpr::store {

struct StoreError {
  std::string operation;  // "fsync", "rename", "parse", ...
  std::string path;       // file or directory the operation touched
  int errno_value = 0;    // 0 when the reason is not an OS error
  std::string reason;     // extra text (parse message, "simulated crash after step 3"); may be empty

  // "rename /var/lib/cdpr-calib/.calibration.toml.tmp: No space left on device"
  std::string message() const;
};

// Builds a StoreError from the current errno.
StoreError errno_error(std::string operation, std::string path);

// A successful operation without a value.
struct Done {};

template <class T>
using StoreResult = Expected<T, StoreError>;

}  // namespace cdpr::store
