// The run marker: its text round-trips, and a daemon that starts with a
// marker left behind reports the interrupted run (time, waypoint k of n) in
// its status. (tests/integration/interrupted_run_test.cc kills a real daemon
// mid-run, restarts it and starts again, which clears the report.)

#include "src/daemon/run_marker.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "../store/store_test_support.h"
#include "daemon_on_fakes.h"
#include "src/formats/run_log_toml.h"

namespace cdpr::daemon {
namespace {

using test::DaemonOnFakes;

RunMarker marker_at_waypoint_7() {
  return RunMarker{"2026-11-25T17:40:02Z", "2026-11-25T17:43:10Z", 7, 35, "settle"};
}

DaemonConfig config_in(const std::string& dir) {
  DaemonConfig config = default_daemon_config();
  config.store.state_dir = dir;
  config.control_socket = dir + "/control";
  return config;
}

TEST(RunMarker, TextRoundTripsAndDescribesTheRun) {
  // GIVEN a marker WHEN formatted and parsed back THEN every field survives
  const RunMarker marker = marker_at_waypoint_7();
  const auto parsed = parse_run_marker(format_run_marker(marker), "run-in-progress.toml");
  ASSERT_TRUE(parsed) << parsed.error().message();
  EXPECT_EQ(parsed->started, marker.started);
  EXPECT_EQ(parsed->updated, marker.updated);
  EXPECT_EQ(parsed->waypoint, 7);
  EXPECT_EQ(parsed->waypoints, 35);
  EXPECT_EQ(parsed->state, "settle");
  // AND its description says when and where the run stopped
  EXPECT_EQ(describe_interrupted_run(marker).substr(0, 60),
            "run interrupted at 2026-11-25T17:43:10Z, waypoint 7 of 35 (s");
}

TEST(RunMarker, ADaemonStartingOverAMarkerReportsTheInterruptedRun) {
  // GIVEN a marker a killed daemon left in the state directory
  store::test::TempStateDir dir;
  const RunMarkerFile file(dir.path());
  ASSERT_TRUE(file.write(marker_at_waypoint_7()));
  // WHEN a daemon starts there
  DaemonOnFakes daemon(config_in(dir.path()));
  ASSERT_TRUE(daemon.start().ok());
  // THEN its status reports the interrupted run, and the marker stays for a daemon restarted again
  const calibration::CalibrationStatus& status = daemon.loop().machine().status();
  EXPECT_EQ(status.interrupted.substr(0, 57), "run interrupted at 2026-11-25T17:43:10Z, waypoint 7 of 35")
      << status.interrupted;
  EXPECT_TRUE(file.read() && file.read()->has_value());
}

TEST(RunMarker, AnInterruptedRunsLogGetsThePlanAndTheTimeItsMarkerKnew) {
  // GIVEN a run killed at waypoint 7 of 35, 191.4 s after its start, before its run.toml was rewritten
  store::test::TempStateDir dir;
  const RunMarkerFile file(dir.path());
  RunMarker marker = marker_at_waypoint_7();
  marker.elapsed_s = 191.4;
  ASSERT_TRUE(file.write(marker));
  const std::string entry = dir.path() + "/history/run-000001";
  std::filesystem::create_directories(entry);
  formats::RunLog running;
  running.run = 1;
  running.started = marker.started;
  std::ofstream(entry + "/run.toml") << formats::format_run_log_toml(running);
  // WHEN a daemon starts there
  DaemonOnFakes daemon(config_in(dir.path()));
  ASSERT_TRUE(daemon.start().ok());
  // THEN the run's log is interrupted with the real plan size and time, not zeros
  const auto log = formats::read_run_log_toml(entry + "/run.toml");
  ASSERT_TRUE(log) << log.error().message();
  EXPECT_EQ(log->outcome, "interrupted");
  EXPECT_EQ(log->waypoints_planned, 35);
  EXPECT_DOUBLE_EQ(log->robot_time_s, 191.4);
  // AND the marker round-trips its elapsed time
  const auto read = file.read();
  ASSERT_TRUE(read && read->has_value());
  EXPECT_DOUBLE_EQ((*read)->elapsed_s, 191.4);
}

TEST(RunMarker, AnUnreadableMarkerStillReportsAnInterruptedRun) {
  // GIVEN a marker cut short
  store::test::TempStateDir dir;
  std::ofstream(dir.path() + "/run-in-progress.toml") << "started = \"2026-11";
  // WHEN a daemon starts THEN it says a run was interrupted, naming the unreadable marker
  DaemonOnFakes daemon(config_in(dir.path()));
  ASSERT_TRUE(daemon.start().ok());
  const std::string& interrupted = daemon.loop().machine().status().interrupted;
  EXPECT_NE(interrupted.find("a run was interrupted (its marker is unreadable: " + dir.path() +
                             "/run-in-progress.toml"),
            std::string::npos)
      << interrupted;
}

TEST(RunMarker, NoMarkerNoReport) {
  // GIVEN a clean state directory WHEN a daemon starts THEN nothing is reported
  store::test::TempStateDir dir;
  DaemonOnFakes daemon(config_in(dir.path()));
  ASSERT_TRUE(daemon.start().ok());
  EXPECT_EQ(daemon.loop().machine().status().interrupted, "");
  EXPECT_TRUE(daemon.loop().machine().status().store_problems.empty());
}

}  // namespace
}  // namespace cdpr::daemon
