// run.toml: what the daemon writes reads back the same, and a damaged or
// newer file is refused with file, line and key.

#include "src/formats/run_log_toml.h"

#include <gtest/gtest.h>

namespace cdpr::formats {
namespace {

RunLog example_log() {
  RunLog log;
  log.run = 7;
  log.outcome = kRunCommitted;
  log.reason = "committed calibration 3 from 33 samples";
  log.robot = "large";
  log.started = "2026-11-26T10:00:00Z";
  log.finished = "2026-11-26T10:14:02Z";
  log.robot_time_s = 842.25;
  log.waypoints_planned = 35;
  log.strategy = "sequential";
  log.stop = "target reached";
  log.samples = 33;
  log.skipped = 2;
  log.calibration = 3;
  log.diagnosis = "model explains the data";
  log.extends = 6;
  log.waypoints.push_back({1, "sampled", 20.5, 0, "re-solve with 11 samples failed: next waypoint in spread order"});
  log.waypoints.push_back({2, "skipped", 85.0, -1, "no equilibrium within 60 s (platform moving: 4.1 mm/s)"});
  log.faults.push_back({90.0, "winch 2: \"heartbeat\" lost"});
  return log;
}

TEST(RunLogToml, WhatIsWrittenReadsBackTheSame) {
  // GIVEN a full log WHEN formatted and parsed THEN every field survives
  const RunLog log = example_log();
  const auto parsed = parse_run_log_toml(format_run_log_toml(log), "run.toml");
  ASSERT_TRUE(parsed) << parsed.error().message();
  EXPECT_EQ(parsed->run, 7);
  EXPECT_EQ(parsed->outcome, "committed");
  EXPECT_EQ(parsed->reason, log.reason);
  EXPECT_EQ(parsed->finished, log.finished);
  EXPECT_EQ(parsed->robot_time_s, 842.25);
  EXPECT_EQ(parsed->calibration, 3);
  EXPECT_EQ(parsed->diagnosis, log.diagnosis);
  EXPECT_EQ(parsed->strategy, "sequential");
  EXPECT_EQ(parsed->extends, 6);
  EXPECT_EQ(parsed->stop, "target reached");
  ASSERT_EQ(parsed->waypoints.size(), 2u);
  EXPECT_EQ(parsed->waypoints[0].why, log.waypoints[0].why);
  EXPECT_EQ(parsed->waypoints[0].sample, 0);
  EXPECT_EQ(parsed->waypoints[1].sample, -1);
  EXPECT_EQ(parsed->waypoints[1].why, log.waypoints[1].why);
  ASSERT_EQ(parsed->faults.size(), 1u);
  EXPECT_EQ(parsed->faults[0].text, log.faults[0].text);
}

TEST(RunLogToml, ARunThatEndedBeforeItsFirstWaypointHasNoTables) {
  // GIVEN a run refused in preflight WHEN its log is written and read THEN no waypoints, no faults
  RunLog log;
  log.run = 1;
  log.outcome = kRunFailed;
  log.started = "2026-11-26T10:00:00Z";
  const auto parsed = parse_run_log_toml(format_run_log_toml(log), "run.toml");
  ASSERT_TRUE(parsed) << parsed.error().message();
  EXPECT_TRUE(parsed->waypoints.empty());
  EXPECT_TRUE(parsed->faults.empty());
}

TEST(RunLogToml, AnUnknownOutcomeOrFormatIsRefusedWithLineAndKey) {
  // GIVEN a log with a misspelt outcome, and one of a newer format
  std::string text = format_run_log_toml(example_log());
  std::string misspelt = text;
  misspelt.replace(misspelt.find("\"committed\""), 11, "\"comitted\"");
  std::string newer = text;
  newer.replace(newer.find("format = 1"), 10, "format = 2");
  // WHEN parsed THEN both are refused naming the file, line and key
  const auto bad_outcome = parse_run_log_toml(misspelt, "run.toml");
  ASSERT_FALSE(bad_outcome);
  EXPECT_NE(bad_outcome.error().message().find("run.toml:3"), std::string::npos) << bad_outcome.error().message();
  EXPECT_NE(bad_outcome.error().message().find("outcome"), std::string::npos);
  const auto bad_format = parse_run_log_toml(newer, "run.toml");
  ASSERT_FALSE(bad_format);
  EXPECT_NE(bad_format.error().message().find("format"), std::string::npos) << bad_format.error().message();
}

}  // namespace
}  // namespace cdpr::formats
