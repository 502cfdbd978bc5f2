#include "src/control/control_dispatch.h"

#include "src/control/control_request.h"
#include "src/control/control_response.h"
#include "src/control/start_waypoints.h"

namespace cdpr::control {

std::string respond(std::string_view request_line, calibration::CalibrationStateMachine& machine,
                    store::CalibrationStore& store, hal::TimeUs now_us, RefitService* refits,
                    const operation::OperationStatus* operation) {
  const auto request = parse_request(request_line);
  if (!request) return format_error_response(request.error());
  switch (request->kind) {
    case RequestKind::kStart: {
      std::optional<calibration::GivenWaypoints> given;
      if (!request->waypoints_path.empty()) {
        if (calibration::is_running(machine.status().state)) {
          return format_error_response("start refused: a calibration is already running");
        }
        auto loaded = load_start_waypoints(request->waypoints_path, request->run, store.history_dir(), machine.robot());
        if (!loaded) return format_error_response("start refused: " + loaded.error());
        given = std::move(*loaded);
      }
      const bool with_waypoints = given.has_value();
      if (!machine.request_start(now_us, std::move(given))) return format_error_response(machine.status().note);
      return format_ok_response(with_waypoints ? machine.status().note : std::string("started"));
    }
    case RequestKind::kAbort:
      if (!machine.request_abort(now_us, "abort requested on the control socket")) {
        return format_error_response(machine.status().note);
      }
      return format_ok_response("aborted: " + machine.status().reason);
    case RequestKind::kStatus:
      return format_status_response(machine.status(), now_us, refits ? refits->refit_status() : std::nullopt,
                                    operation);
    case RequestKind::kResetFaults:
      if (!machine.request_reset_faults(now_us)) return format_error_response(machine.status().note);
      return format_ok_response(machine.status().note);
    case RequestKind::kShow: {
      const auto current = store.load_current();
      if (!current) {
        return format_error_response("the current calibration is unreadable: " + current.error().message());
      }
      std::optional<store::RunEntry> run;
      if (*current) run = store::RunHistory(store.history_dir()).find_by_calibration((*current)->text);
      return format_show_response(*current, run);
    }
    case RequestKind::kHistory: {
      const auto history = store.history();
      if (!history) return format_error_response(history.error().message());
      return format_history_response(*history);
    }
    case RequestKind::kRollback: {
      if (calibration::is_running(machine.status().state)) {
        return format_error_response("rollback refused: a calibration is running (abort it first)");
      }
      const auto rolled = store.rollback(request->seq);
      machine.refresh_store_problems();
      if (!rolled) return format_error_response("rollback to " + std::to_string(request->seq) + " failed: " +
                                                rolled.error().message());
      return format_ok_response("calibration " + std::to_string(*rolled) + " is current");
    }
    case RequestKind::kCommit:
      if (!machine.request_commit_kept(now_us)) return format_error_response(machine.status().note);
      return format_ok_response(machine.status().note);
    case RequestKind::kRefit: {
      if (calibration::is_running(machine.status().state)) {
        return format_error_response("refit refused: a calibration is running (wait for its end or abort it)");
      }
      if (!refits) return format_error_response("refit refused: this daemon cannot refit runs");
      const auto started = refits->start_refit(request->run, request->terms);
      if (!started) return format_error_response("refit refused: " + started.error());
      return format_ok_response(*started);
    }
  }
  return format_error_response("unhandled request");
}

}  // namespace cdpr::control
