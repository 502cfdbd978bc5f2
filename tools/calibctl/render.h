#pragma once
// Human-readable text of the control socket's responses
// (src/control/control_response.h) for calibctl. Pure functions.

#include <string>

#include "calibctl/json_value.h"

namespace cdpr::calibctl {

// "settle  waypoint 3/35  samples 2  skipped 0  12%  41.2 s" plus lines for
// detail, note and reason when present.
std::string render_status(const JsonValue& status);
// One line for `status --follow`: "[ 12%] settle 3/35 (2 sampled, 0 skipped) platform moving: ...".
std::string render_progress(const JsonValue& status);
// The current calibration: one line per winch with anchor, offset and sigmas,
// the fit, then the model warning and the rejected readings when there are any.
std::string render_show(const JsonValue& show);
// The outcome of the last refit (status "refit"): "refit of run-000007 with
// load_cell_bias: committed: committed calibration 5: ..." plus its entry.
std::string render_refit(const JsonValue& refit);

// The stored versions, newest first, the current one marked.
std::string render_history(const JsonValue& history);

}  // namespace cdpr::calibctl
