#include "drivers/common/posix_status.h"

#include <cerrno>
#include <cstring>
#include <string>

namespace cdpr::drivers {

hal::ErrorCode error_code_from_errno(int error_number) {
  switch (error_number) {
    case ETIMEDOUT:
    case EAGAIN:
      return hal::ErrorCode::kTimeout;
    case ECONNREFUSED:
    case ECONNRESET:
    case ECONNABORTED:
    case EPIPE:
    case ENOTCONN:
    case ENOENT:
    case EHOSTUNREACH:
    case ENETUNREACH:
    case ENODEV:
    case ENXIO:
      return hal::ErrorCode::kNotConnected;
    case EAFNOSUPPORT:
    case EPROTONOSUPPORT:
    case ENOSYS:
    case EOPNOTSUPP:
      return hal::ErrorCode::kUnsupported;
    case EINVAL:
      return hal::ErrorCode::kInvalidArgument;
    default:
      return hal::ErrorCode::kIoError;
  }
}

hal::Status status_from_errno(int error_number, std::string_view device, std::string_view operation) {
  std::string message(device);
  message += ": ";
  message += operation;
  message += ": ";
  message += std::strerror(error_number);
  return hal::Status(error_code_from_errno(error_number), std::move(message));
}

}  // namespace cdpr::drivers
