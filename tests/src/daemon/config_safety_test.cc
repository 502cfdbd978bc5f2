// Values that would defeat a safety function of the robot (issue 34: each
// was accepted once and the daemon said ready): refused at parse time with
// file, line and key, or accepted only where unsafe_ok acknowledges them;
// a device endpoint has no default; the paths are checked before anything
// is opened.

#include <unistd.h>

#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "../store/store_test_support.h"
#include "config_text.h"
#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {
namespace {

using test::config_text;

struct Refusal {
  std::string text;     // after `robot = "r"`; the endpoints the case leaves out are added
  std::string message;  // the whole refusal: file:line: key: reason
};

void expect_full_refusal(const Refusal& c) {
  // GIVEN a configuration with one unsafe value WHEN parsed
  const auto config = parse_daemon_config(config_text(c.text), "cdpr-calibd.toml");
  // THEN it is refused, naming file, line and key and saying why
  ASSERT_FALSE(config) << c.text;
  EXPECT_EQ(config.error().message(), c.message);
}

TEST(ConfigSafety, TimeoutsBeyondTheirRangeAreRefused) {
  const Refusal cases[] = {
      {"[winches]\nendpoint = \"socketcan:can0\"\nheartbeat_timeout_ms = 99999999999999\n",
       "cdpr-calibd.toml:4: winches.heartbeat_timeout_ms: must be in [10, 60000], got 99999999999999"},
      {"[limits]\npose_stale_ms = 3600000000\n",
       "cdpr-calibd.toml:3: limits.pose_stale_ms: must be in [1, 60000], got 3.6e+09"},
      {"[load_cell]\nendpoint = \"rtu:/dev/ttyS0\"\nfault_timeout_ms = 86400000000\n",
       "cdpr-calibd.toml:4: load_cell.fault_timeout_ms: must be in [10, 60000], got 8.64e+10"},
      {"[winches.drive]\nconsumer_heartbeat_ms = 4e9\n",
       "cdpr-calibd.toml:3: winches.drive.consumer_heartbeat_ms: must be in [10, 65535], got 4e+09"},
  };
  for (const Refusal& c : cases) expect_full_refusal(c);
}

TEST(ConfigSafety, MotionAndForceBeyondTheirRangeAreRefused) {
  const Refusal cases[] = {
      {"[winches.drive]\nquick_stop_deceleration_mps2 = 1e-6\n",
       "cdpr-calibd.toml:3: winches.drive.quick_stop_deceleration_mps2: must be in [0.5, 20], got 1e-06"},
      {"[winches.drive]\nprofile_velocity_mps = 1e6\n",
       "cdpr-calibd.toml:3: winches.drive.profile_velocity_mps: must be in (0, 10], got 1e+06"},
      {"[limits]\nmax_tension = 1e15\n",
       "cdpr-calibd.toml:3: limits.max_tension: must be in (0, 1e+05], got 1e+15"},
      {"[waypoints]\nmax_tension = 1e15\n",
       "cdpr-calibd.toml:3: waypoints.max_tension: must be in (0, 1e+05], got 1e+15"},
  };
  for (const Refusal& c : cases) expect_full_refusal(c);
}

TEST(ConfigSafety, AWholeNumberKeyRefusesAFraction) {
  const Refusal cases[] = {
      // 0x1016 and 0x1017 hold whole milliseconds: 2000.5 would be cut to 2000 in the drive
      {"[winches.drive]\nconsumer_heartbeat_ms = 2000.5\n",
       "cdpr-calibd.toml:3: winches.drive.consumer_heartbeat_ms: must be a whole number, got 2000.5"},
      {"[winches.encoder]\nheartbeat_producer_ms = 100.5\n",
       "cdpr-calibd.toml:3: winches.encoder.heartbeat_producer_ms: must be a whole number, got 100.5"},
      {"[waypoints]\ncount = 2000.5\n",
       "cdpr-calibd.toml:3: waypoints.count: expected an integer, got a number"},
  };
  for (const Refusal& c : cases) expect_full_refusal(c);
}

TEST(ConfigSafety, KeysThatDisagreeWithTheSafetyRulesAreRefused) {
  const Refusal cases[] = {
      // CiA 301: a consumer time of 1.5 producer periods takes one late heartbeat
      {"[winches]\nendpoint = \"socketcan:can0\"\nheartbeat_timeout_ms = 50\n",
       "cdpr-calibd.toml:4: winches.heartbeat_timeout_ms: winches.heartbeat_timeout_ms (50 ms) must be at least "
       "1.5 x winches.drive.heartbeat_producer_ms (100 ms): a drive would be lost between two of its heartbeats"},
      {"[winches]\nendpoint = \"socketcan:can0\"\nheartbeat_timeout_ms = 500\n[winches.encoder]\n"
       "heartbeat_producer_ms = 400\n",
       "cdpr-calibd.toml:6: winches.encoder.heartbeat_producer_ms: winches.heartbeat_timeout_ms (500 ms) must be at "
       "least 1.5 x winches.encoder.heartbeat_producer_ms (400 ms): an encoder would be lost between two of its "
       "heartbeats"},
      {"[winches.drive]\nconsumer_heartbeat_ms = 120\n",
       "cdpr-calibd.toml:3: winches.drive.consumer_heartbeat_ms: winches.drive.consumer_heartbeat_ms (120 ms) must "
       "be at least 1.5 x winches.master_heartbeat_ms (100 ms): the drives would stop between two of the daemon's "
       "heartbeats"},
      {"[winches.drive]\nprofile_deceleration_mps2 = 3.0\n",
       "cdpr-calibd.toml:3: winches.drive.profile_deceleration_mps2: winches.drive.quick_stop_deceleration_mps2 "
       "(2 m/s^2) must be at least winches.drive.profile_deceleration_mps2 (3 m/s^2): a quick stop (abort, lost "
       "heartbeat) must not stop later than a planned stop"},
      {"[winches]\nendpoint = \"socketcan:can0\"\nmax_speed_mps = 1.5\n",
       "cdpr-calibd.toml:4: winches.max_speed_mps: winches.drive.profile_velocity_mps (2 m/s) must be below "
       "winches.max_speed_mps (1.5 m/s): the encoder jump check would stop every move"},
  };
  for (const Refusal& c : cases) expect_full_refusal(c);
}

TEST(ConfigSafety, ADeviceEndpointHasNoDefault) {
  // GIVEN a configuration without [winches] endpoint (it once became socketcan:can0)
  const auto config = parse_daemon_config(
      "robot = \"r\"\n[winches]\nmax_move_m = 100.0\n[load_cell]\nendpoint = \"rtu:/dev/ttyS0\"\n"
      "[pose]\nendpoint = \"tcp:127.0.0.1:5600\"\n",
      "cdpr-calibd.toml");
  // THEN it is refused naming the table's line and the key
  ASSERT_FALSE(config);
  EXPECT_EQ(config.error().message().substr(0, 52), "cdpr-calibd.toml:2: winches.endpoint: missing requir")
      << config.error().message();
  // AND so are the load cell's and the pose stream's
  for (const std::string table : {"load_cell", "pose"}) {
    std::string text = config_text("");
    const std::size_t header = text.find("[" + table + "]\n");
    text.erase(header, text.find('\n', text.find('\n', header) + 1) - header + 1);
    const auto missing = parse_daemon_config(text, "c.toml");
    ASSERT_FALSE(missing) << text;
    EXPECT_EQ(missing.error().field, table + ".endpoint") << missing.error().message();
  }
}

TEST(ConfigSafety, AValueThatDefeatsASafetyFunctionNeedsUnsafeOk) {
  // GIVEN drives told not to react to the daemon's lost heartbeat
  const std::string unsafe = "[winches.drive]\nabort_connection_option = 0\n";
  // WHEN parsed without an acknowledgement THEN refused, saying what is given up and how to accept it
  expect_full_refusal({unsafe,
                  "cdpr-calibd.toml:3: winches.drive.abort_connection_option: 0: the drives would keep moving with "
                  "the daemon gone (no reaction to a lost heartbeat); to run so all the same, list "
                  "\"winches.drive.abort_connection_option\" in unsafe_ok"});
  // AND with it listed in unsafe_ok it is accepted and named for the start-up log
  const auto acknowledged = parse_daemon_config(
      config_text("unsafe_ok = [\"winches.drive.abort_connection_option\"]\n" + unsafe), "c.toml");
  ASSERT_TRUE(acknowledged) << acknowledged.error().message();
  EXPECT_EQ(acknowledged->winches.drive.abort_connection_option, 0);
  ASSERT_EQ(acknowledged->unsafe_accepted.size(), 1u);
  EXPECT_EQ(acknowledged->unsafe_accepted[0].key, "winches.drive.abort_connection_option");
  EXPECT_EQ(acknowledged->unsafe_accepted[0].line, 4);
}

TEST(ConfigSafety, LongSafetyTimeoutsNeedUnsafeOk) {
  const Refusal cases[] = {
      {"[winches]\nendpoint = \"socketcan:can0\"\nheartbeat_timeout_ms = 3000\n",
       "cdpr-calibd.toml:4: winches.heartbeat_timeout_ms: longer than 1000 ms: a lost drive or encoder would go "
       "unnoticed while the others pull; to run so all the same, list \"winches.heartbeat_timeout_ms\" in "
       "unsafe_ok"},
      {"[limits]\npose_stale_ms = 3000\n", "cdpr-calibd.toml:3: limits.pose_stale_ms: longer than 1000 ms"},
      {"[winches.drive]\nconsumer_heartbeat_ms = 1500\n",
       "cdpr-calibd.toml:3: winches.drive.consumer_heartbeat_ms: longer than 1000 ms"},
      {"[load_cell]\nendpoint = \"rtu:/dev/ttyS0\"\nfault_timeout_ms = 3000\n",
       "cdpr-calibd.toml:4: load_cell.fault_timeout_ms: longer than 2000 ms"},
  };
  for (const Refusal& c : cases) {
    const auto config = parse_daemon_config(config_text(c.text), "cdpr-calibd.toml");
    ASSERT_FALSE(config) << c.text;
    EXPECT_EQ(config.error().message().substr(0, c.message.size()), c.message);
  }
  // GIVEN the same values acknowledged (a virtual robot on a loaded test machine) THEN accepted
  const auto acknowledged = parse_daemon_config(
      config_text("unsafe_ok = [\"winches.heartbeat_timeout_ms\", \"limits.pose_stale_ms\", "
                  "\"winches.drive.consumer_heartbeat_ms\", \"load_cell.fault_timeout_ms\"]\n"
                  "[winches]\nendpoint = \"socketcan:can0\"\nheartbeat_timeout_ms = 3000\n"
                  "[winches.drive]\nconsumer_heartbeat_ms = 1500\n"
                  "[load_cell]\nendpoint = \"rtu:/dev/ttyS0\"\nfault_timeout_ms = 3000\n[limits]\npose_stale_ms = 3000\n"),
      "c.toml");
  ASSERT_TRUE(acknowledged) << acknowledged.error().message();
  EXPECT_EQ(acknowledged->unsafe_accepted.size(), 4u);
}

TEST(ConfigSafety, UnsafeOkNamesOnlyKeysThatCanBeAcknowledged) {
  // GIVEN unsafe_ok naming a key without unsafe values (a typo would acknowledge nothing)
  const auto config = parse_daemon_config(config_text("unsafe_ok = [\"winches.drive.abort_conection_option\"]\n"),
                                          "c.toml");
  // THEN refused, listing the keys it may name
  ASSERT_FALSE(config);
  EXPECT_EQ(config.error().field, "unsafe_ok");
  EXPECT_EQ(config.error().line, 2);
  EXPECT_NE(config.error().message().find("\"winches.drive.abort_connection_option\""), std::string::npos)
      << config.error().message();
}

TEST(ConfigSafety, TheRobotFileAndTheStateDirectoryAreCheckedBeforeStart) {
  store::test::TempStateDir dir;
  const std::string robot = dir.path() + "/robot.toml";
  const std::string not_a_dir = dir.path() + "/state";
  std::ofstream(robot) << "# robot\n";
  std::ofstream(not_a_dir) << "a file\n";
  const auto config_for = [&](const std::string& robot_path, const std::string& state_dir) {
    return parse_daemon_config(test::with_endpoints("robot = \"" + robot_path + "\"\n[store]\nstate_dir = \"" +
                                                     state_dir + "\"\n"),
                               "cdpr-calibd.toml");
  };
  // GIVEN a robot file that is not there, and a state directory that is a file
  const auto missing_robot = config_for(dir.path() + "/no-robot.toml", dir.path() + "/new-state");
  const auto state_is_a_file = config_for(robot, not_a_dir);
  const auto fine = config_for(robot, dir.path() + "/new-state");
  ASSERT_TRUE(missing_robot && state_is_a_file && fine);
  // WHEN their paths are checked THEN each is refused naming file, line and key
  const auto no_robot = check_config_paths(*missing_robot);
  ASSERT_TRUE(no_robot.has_value());
  EXPECT_EQ(no_robot->message(), "cdpr-calibd.toml:1: robot: cannot read \"" + dir.path() +
                                     "/no-robot.toml\": No such file or directory");
  const auto file_state = check_config_paths(*state_is_a_file);
  ASSERT_TRUE(file_state.has_value());
  EXPECT_EQ(file_state->message(), "cdpr-calibd.toml:3: store.state_dir: \"" + not_a_dir + "\" is not a directory");
  EXPECT_FALSE(check_config_paths(*fine).has_value());
}

}  // namespace
}  // namespace cdpr::daemon
