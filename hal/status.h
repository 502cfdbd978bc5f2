#pragma once
// The result of every hardware call: ok, or an error code with a message for
// the operator. Drivers translate errno, libmodbus and CANopen failures into
// these codes at their boundary, so the daemon decides on the code (retry,
// skip the waypoint, abort) and shows the message (docs/STYLE.md "one policy per
// layer"; ros2_control return_type).
//
// Real-time safety: an ok Status holds an empty std::string and does not
// allocate; building an error message may allocate. Copying is cheap when ok.
// Thread safety: a value type; no shared state.

#include <string>
#include <utility>

namespace cdpr::hal {

enum class ErrorCode {
  kOk = 0,
  kTimeout,          // no answer within the response timeout (after retries)
  kNotConnected,     // transport closed, refused, reset or never opened
  kIoError,          // other operating-system error on the transport
  kCorruptData,      // checksum (CRC) or framing error in a reply
  kProtocolError,    // reply well formed but not what the protocol allows (exception, wrong id)
  kDeviceFault,      // the device reports a fault (CiA 402 fault state, load cell error bit)
  kNodeDead,         // a CANopen node missed its heartbeat
  kInvalidArgument,  // caller error: bad winch index, non-finite target, bad config value
  kInvalidState,     // call not allowed now (command before enable, read before open)
  kUnsupported,      // feature not compiled in or not available on this machine
};

// Short stable name of a code ("timeout", "not connected", ...).
constexpr const char* to_string(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk: return "ok";
    case ErrorCode::kTimeout: return "timeout";
    case ErrorCode::kNotConnected: return "not connected";
    case ErrorCode::kIoError: return "i/o error";
    case ErrorCode::kCorruptData: return "corrupt data";
    case ErrorCode::kProtocolError: return "protocol error";
    case ErrorCode::kDeviceFault: return "device fault";
    case ErrorCode::kNodeDead: return "node dead";
    case ErrorCode::kInvalidArgument: return "invalid argument";
    case ErrorCode::kInvalidState: return "invalid state";
    case ErrorCode::kUnsupported: return "unsupported";
  }
  return "unknown";
}

class [[nodiscard]] Status {
 public:
  Status() = default;  // ok
  Status(ErrorCode code, std::string message) : code_(code), message_(std::move(message)) {}

  static Status Ok() { return Status(); }

  bool ok() const { return code_ == ErrorCode::kOk; }
  ErrorCode code() const { return code_; }
  // Human-readable reason naming the device and the cause, e.g.
  // "load cell 127.0.0.1:1502: timeout after 3 tries (500 ms each)". Empty when ok.
  const std::string& message() const { return message_; }
  // "<code>: <message>" for logs and the control socket.
  std::string to_string() const {
    if (ok()) return "ok";
    return std::string(hal::to_string(code_)) + ": " + message_;
  }

 private:
  ErrorCode code_ = ErrorCode::kOk;
  std::string message_;
};

// A value or the Status saying why there is none. value() on an error is a
// broken invariant of the caller (checked by assertion in debug builds only:
// test ok() first).
template <typename T>
class [[nodiscard]] Result {
 public:
  Result(T value) : value_(std::move(value)) {}  // NOLINT: implicit on purpose
  // From an error. An ok Status here is a caller bug; it becomes an
  // kInvalidState error rather than an "ok" result without a value.
  Result(Status status)  // NOLINT: implicit on purpose
      : status_(status.ok() ? Status(ErrorCode::kInvalidState, "result built from an ok status without a value")
                            : std::move(status)) {}

  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  const T& value() const { return value_; }
  T& value() { return value_; }

 private:
  Status status_;
  T value_{};
};

}  // namespace cdpr::hal
