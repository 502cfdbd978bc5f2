#include "src/daemon/operation_config_table.h"

namespace cdpr::daemon {

Table<OperationConfig> operation_table() {
  constexpr TimeUnit kS = TimeUnit::kSeconds;
  Table<OperationConfig> t("operation");
  t.boolean("watch", &OperationConfig::watch, false,
            "between runs only listen on the CAN bus (the robot's controller owns the drives: the daemon sends no "
            "frame), find the platform's rests, serve their pose from the cables and check them against the "
            "calibration (docs/operation.md)");
  t.string("pose_output", &OperationConfig::pose_output, "",
           "\"unix:<path>\": a pose line with its covariance per rest for the controller (docs/FORMATS.md); "
           "absent: not served")
      .refusing("unix:<path>", [](const OperationConfig& c) -> std::string {
        if (c.pose_output.empty() || (c.pose_output.rfind("unix:", 0) == 0 && c.pose_output.size() > 5)) return "";
        return "\"" + c.pose_output + "\" is not unix:<path>";
      });
  t.duration("rest_window_s", &OperationConfig::rest_window_us, 2.0, kS, {0.1, 600},
             "watch: the rest window averaged into one rest (the [equilibrium] thresholds apply)")
      .why("at least a few poses; beyond 10 minutes no production rest is seen");
  t.duration("return_window_s", &OperationConfig::return_window_us, 6.0, kS, {0.2, 3600},
             "watch: how far back a rest must not have come back from a sway; the shortest rest seen is this long")
      .why("at least two rest windows make sense; an hour is longer than any rest");
  t.number("clean_rests_per_false_alarm", &OperationConfig::clean_rests_per_false_alarm, 1000.0, {10.0, 1e9}, "",
           "watch: the health test's designed false-alarm rate, at most one `calibration stale` per this many rests "
           "of a right calibration (its CUSUM threshold, solver/operation/health_watch.h)")
      .why("below 10 every few rests would be an alarm; beyond 1e9 a change is never flagged");
  t.integer("drive_tpdo_base", [](auto& c) -> auto& { return c.listen.drive_tpdo_base; }, 0x180, {0x080, 0x680, true},
            "", "watch: the drives' TPDO with statusword and position is this + node id (CiA 402 TPDO1: 0x180)")
      .why("node ids up to 127 on top must stay within 0x7FF");
  t.integer("drive_statusword_byte", [](auto& c) -> auto& { return c.listen.drive_statusword_byte; }, 0, {-1, 6}, "",
            "watch: byte of statusword 0x6041 in that TPDO; -1: not mapped")
      .why("2 bytes in an 8-byte frame");
  t.integer("drive_position_byte", [](auto& c) -> auto& { return c.listen.drive_position_byte; }, 2, {-1, 4}, "",
            "watch: byte of position actual 0x6064 in that TPDO (the payout of winches without an encoder); -1: not mapped")
      .why("4 bytes in an 8-byte frame");
  t.integer("encoder_tpdo_base", [](auto& c) -> auto& { return c.listen.encoder_tpdo_base; }, 0x180,
            {0x080, 0x680, true}, "", "watch: the encoders' position TPDO is this + node id (CiA 406 TPDO1: 0x180)")
      .why("node ids up to 127 on top must stay within 0x7FF");
  t.integer("encoder_position_byte", [](auto& c) -> auto& { return c.listen.encoder_position_byte; }, 0, {0, 4}, "",
            "watch: byte of position value 0x6004 in that TPDO (unwrapped across [winches.encoder] measuring_range)")
      .why("4 bytes in an 8-byte frame");
  return t;
}

}  // namespace cdpr::daemon
