#pragma once
// The control socket's request language (the daemon's Unix stream socket,
// e.g. /run/cdpr-calib/control; client: calibctl).
//
// One request per line, ASCII, terminated by "\n" (a "\r" before it is
// accepted), at most kMaxRequestBytes bytes without the terminator; words
// separated by single or repeated spaces or tabs:
//
//   start            start a calibration (as the button)
//   start waypoints <path> [<run>]  a calibration through exactly the
//                    waypoints of the waypoints.csv at <path> (absolute, no
//                    blanks; read by the daemon), its data appended to run
//                    <run>'s samples when given (7 or run-000007)
//   abort            abort the calibration in progress
//   status           state, waypoint k/N, progress, reasons
//   show             the current calibration
//   history          the stored versions
//   rollback <seq>   make stored version <seq> current again (seq: 1..999999999)
//   commit           commit the fit a failed commit kept in <state>/pending
//   refit <terms> [<run>]  re-fit a kept run's samples with the catenary plus
//                    <terms> (model term names, comma-separated, e.g.
//                    load_cell_bias) and commit it when it validates; <run>:
//                    7 or run-000007, the newest kept run when absent
//   reset-faults     clear the devices' latched faults (not during a run)
//
// Every request gets exactly one response line (control_response.h). The
// parser accepts any byte sequence without crashing and refuses everything
// not listed above with a reason (fuzzed in tests/src/control).

#include <string>
#include <string_view>

#include "src/formats/expected.h"

namespace cdpr::control {

inline constexpr std::size_t kMaxRequestBytes = 256;

enum class RequestKind {
  kStart, kAbort, kStatus, kShow, kHistory, kRollback, kCommit, kResetFaults, kRefit
};

const char* to_string(RequestKind kind);

struct Request {
  RequestKind kind = RequestKind::kStatus;
  int seq = 0;  // kRollback only
  // kRefit only: the terms as given (checked against the known ones by the
  // daemon, which names them in its refusal) and the run, 0 for the newest.
  std::string terms;
  int run = 0;
  // kStart with waypoints: the file (absolute); `run` the run to append to, 0 for none.
  std::string waypoints_path;
};

// Parses one line (with or without its "\n"). The error is a short reason
// for the client, e.g. "unknown command 'strat' (expected start, abort, ...)".
Expected<Request, std::string> parse_request(std::string_view line);

}  // namespace cdpr::control
