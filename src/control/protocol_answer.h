#pragma once
// The two answers any side of the control socket can give on its own, one
// JSON line each: {"ok":false,"error":...} and {"ok":true,"message":...}.
// Apart from the daemon's other responses (control_response.h) so that
// calibctl, which answers for a daemon it cannot reach, links this alone
// (the cdpr_control_protocol library) and not the daemon.
// Strings are escaped by nlohmann, invalid UTF-8 replaced by U+FFFD: no
// newline or invalid text gets through whatever a reason holds.

#include <string>
#include <string_view>

namespace cdpr::control {

std::string format_error_response(std::string_view reason);
std::string format_ok_response(std::string_view message);

}  // namespace cdpr::control
