#pragma once
// Responses of the control socket: exactly one line per request, a JSON
// object terminated by "\n", never containing another newline.
//
//   error (any request)  {"ok":false,"error":"unknown command 'strat' (...)"}
//   start/abort/rollback/commit {"ok":true,"message":"started"}
//   status   {"ok":true,"state":"settle","running":true,"waypoint":3,"waypoints":35,
//             "samples":2,"skipped":0,"progress":0.12,"elapsed_s":41.2,
//             "reason":"","note":"","detail":"platform moving: ...","device_faults":"",
//             "committed_seq":0,"interrupted":"","store_problems":[],"pending_commit":false,
//             "run":{"entry":"/var/lib/cdpr-calib/history/run-000007","outcome":"running","samples":2,
//                    "diagnosis":"","named_terms":[]},
//             "refit":{"run":"run-000007","terms":"load_cell_bias","state":"committed","message":"..",
//                      "committed_seq":5,"entry":"/var/lib/cdpr-calib/history/run-000008"}}
//            elapsed_s: since the last run started (to its end when finished); null if never run
//            device_faults: the devices' latched faults until reset-faults ("" when none)
//            interrupted: "run interrupted at <time>, waypoint k of n ..." when a daemon died
//            mid-run, until the next start; store_problems: unreadable stored files, one
//            sentence each; pending_commit: a failed commit's fit waits for `commit`;
//            run: the last run's history entry (docs/FORMATS.md "History entry of a run"; entry
//            "" when none is kept), its outcome as in run.toml, its samples, the model check's
//            verdict ("" until it ran) and the model terms that verdict names (what
//            `refit <terms>` would add); null before a run
//            refit: the last refit requested (refit_service.h: state running, committed,
//            refused or failed); null before the first
//            nodes: every bus node of the winches, [{"winch":0,"role":"drive","node_id":1,
//            "nmt":"operational","configured":true,"cia402":"quick stop active","error_code":"",
//            "last_emcy":"0x8130 (life guard or heartbeat error)","emcy_register":17,
//            "pdo_age_ms":12.5,"heartbeat_age_ms":40},...]: NMT state of its heartbeat ("silent"
//            past the heartbeat timeout, "unknown" never heard), CiA 402 power state (drives;
//            "" before a statusword), 0x603F while in fault, the last EMCY since the bus was
//            opened, ages null when never heard
//            operation: watch mode ([operation] watch, docs/operation.md), null when
//            not watching: {"mode":"watch","state":"watching","calibration_seq":4,"rests":12,
//            "localized":12,"detail":"at rest","last_problem":"",
//            "last_rest":{"rest":12,"age_s":3.1,"position":[x,y,z],"position_sigma":[..],
//            "orientation_sigma":[..],"onboard_sigmas":1.2},
//            "finding":{"term":"offset[2]","meaning":"encoder offset slip of cable 2","cable":2,
//            "value":[0.021],"sigma":[0.002],"since_rest":7,"fired_at_rest":9,"fired_s_ago":40.5,
//            "rests_fitted":3,"calibration_fault":true,"alike":[]},
//            "refit":"kept in pending/ for `calibctl commit` (...)"}: state "no calibration",
//            "waiting for a rest", "watching" or "calibration stale"; last_rest null before the
//            first rest localized from the cables; finding null until the health test fires
//            (solver/operation/health_watch.h: term names and units); refit what became of the
//            offered re-fit ("" before)
//   show     {"ok":true,"present":true,"seq":4,"created":"2026-11-22T10:15:00Z","robot":"large",
//             "model":["catenary"],"samples":35,
//             "winches":[{"anchor":[x,y,z],"anchor_sigma":[..],"offset":3.2,"offset_sigma":0.03},...],
//             "fit":{"cost_initial":..,"cost_final":..,"iterations":14,"rms_encoder":..,"rms_force":..},
//             "model_warning":"","rejected":[{"row":12,"sensor":"encoder","cable":3,"residual":-95.4},...],
//             "run":{"entry":"/var/lib/cdpr-calib/history/run-000007","outcome":"committed","samples":35,
//                    "skipped":0,"robot_time_s":812.5,"diagnosis":"","named_terms":[],
//                    "report":"/var/lib/cdpr-calib/history/run-000007/report.html"}}
//            model_warning: why the model does not fit the data ("" when it fits); rejected: the
//            readings left out of the fit as gross errors (calibration.toml [[rejected]]; residual
//            in sigmas at the robust fit); run: the history entry of the run that produced this
//            calibration (its samples, robot.toml and run.toml), null when none is kept
//            {"ok":true,"present":false} when nothing was ever committed
//   history  {"ok":true,"history":[{"seq":4,"current":true,"valid":true,"created":"..","robot":"..",
//             "samples":35,"problem":""},...]}   newest first
// Units as in calibration.toml (m, N); progress in [0, 1]. Members come in
// the order shown; numbers are the shortest text that reads back exactly
// (1e-04, 41), non-finite ones null.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hal/clock.h"
#include "src/calibration/calibration_state.h"
#include "src/control/protocol_answer.h"
#include "src/control/refit_service.h"
#include "src/operation/operation_watch.h"
#include "src/store/calibration_store.h"
#include "src/store/run_history.h"

namespace cdpr::control {

std::string format_status_response(const calibration::CalibrationStatus& status, hal::TimeUs now_us,
                                   const std::optional<RefitStatus>& refit = std::nullopt,
                                   const operation::OperationStatus* operation = nullptr);
std::string format_show_response(const std::optional<store::CurrentCalibration>& current,
                                 const std::optional<store::RunEntry>& run = std::nullopt);
std::string format_history_response(const std::vector<store::HistoryEntry>& history);

}  // namespace cdpr::control
