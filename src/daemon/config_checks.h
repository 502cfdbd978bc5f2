#pragma once
// Checks of cdpr-calibd.toml that span several keys or look inside a
// string (chrony conf.c checks each directive alone; these catch what only
// shows in combination): every limit pair ordered, every band non-empty,
// every endpoint in a form its transport accepts, the load cell's unit
// identifier one its transport takes and its status register clear of the
// value's. Each refusal names the
// file, the line and the key (the key of the pair set in the file, the
// later one when both are), so the daemon stops before it says ready
// instead of retrying or failing in the middle of a run.

#include <optional>

#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {

// nullopt when the keys agree with each other.
std::optional<FormatError> check_cross_keys(const DaemonConfig& config);

}  // namespace cdpr::daemon
