#pragma once
// errno -> hal::Status at the driver boundary (docs/STYLE.md: translate errno into
// our own error). The message names the device and the failed operation.

#include <string_view>

#include "hal/status.h"

namespace cdpr::drivers {

// Code for an errno value: ETIMEDOUT/EAGAIN -> kTimeout; refused, reset,
// broken pipe, no such socket path -> kNotConnected; EAFNOSUPPORT and friends
// -> kUnsupported; EINVAL -> kInvalidArgument; everything else kIoError.
hal::ErrorCode error_code_from_errno(int error_number);

// Status "<device>: <operation>: <strerror>" with the code above.
hal::Status status_from_errno(int error_number, std::string_view device, std::string_view operation);

}  // namespace cdpr::drivers
