// cdpr-calibd.toml keys that are each in range but disagree with each other,
// and endpoints a transport would never accept: refused at parse time with
// file, line and key, before the daemon says ready.

#include <string>

#include <gtest/gtest.h>

#include "../../solver/model/test_robots.h"
#include "config_text.h"
#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {
namespace {

struct Case {
  std::string text;  // after `robot = "r"`
  int line;          // of the blamed key, counted with the robot line
  std::string field;
  std::string words;  // part of the reason
};

void expect_refused(const Case& c) {
  // GIVEN a configuration whose keys disagree WHEN parsed
  const auto config = parse_daemon_config(test::config_text(c.text), "cdpr-calibd.toml");
  // THEN it is refused naming file, line and key, and saying why
  ASSERT_FALSE(config) << c.text;
  EXPECT_EQ(config.error().file, "cdpr-calibd.toml");
  EXPECT_EQ(config.error().field, c.field) << config.error().message();
  EXPECT_EQ(config.error().line, c.line) << config.error().message();
  EXPECT_NE(config.error().message().find(c.words), std::string::npos) << config.error().message();
}

TEST(ConfigChecks, LimitPairsMustBeOrdered) {
  const Case cases[] = {
      {"[limits]\nmin_tension = 600.0\nmax_tension = 500.0\n", 4, "limits.max_tension",
       "limits.min_tension (600 N) must be below limits.max_tension (500 N)"},
      {"[limits]\nmin_tension = 6000.0\n", 3, "limits.min_tension", "must be below limits.max_tension (5000 N)"},
      {"[waypoints]\nmax_tension = 10.0\n", 3, "waypoints.max_tension", "must be below"},
      {"[waypoints]\nz_min = 30.0\nz_max = 10.0\n", 4, "waypoints.z_max", "waypoints.z_min (30 m) must be below"},
      {"[waypoints]\nz_min = 35.0\n", 3, "waypoints.z_min", "must be below waypoints.z_max"},
      {"[waypoints]\nmin_payout = 5.0\nmax_payout = 5.0\n", 4, "waypoints.max_payout", "must be below"},
      {"[waypoints]\nmin_tension = 5.0\n", 3, "waypoints.min_tension", "below limits.min_tension"},
      {"[waypoints]\nmax_tension = 6000.0\n", 3, "waypoints.max_tension", "above limits.max_tension"},
  };
  for (const Case& c : cases) expect_refused(c);
}

TEST(ConfigChecks, CountsAndTimesMustLeaveARunPossible) {
  const Case cases[] = {
      {"[validation]\nmin_samples = 40\n", 3, "validation.min_samples", "more than waypoints.count (35)"},
      {"[waypoints]\ncount = 5\n", 3, "waypoints.count", "validation.min_samples (10) is more than"},
      {"[equilibrium]\nmin_samples = 50\ncapacity = 40\n", 3, "equilibrium.min_samples", "equilibrium.capacity"},
      {"[limits]\nsettle_timeout_s = 2.0\n", 3, "limits.settle_timeout_s", "longer than equilibrium.window_s"},
      {"[limits]\npose_stale_ms = 20\n", 3, "limits.pose_stale_ms", "longer than loop.period_ms"},
  };
  for (const Case& c : cases) expect_refused(c);
}

TEST(ConfigChecks, EveryEndpointMustSuitItsTransport) {
  const Case cases[] = {
      {"[winches]\nendpoint = \"can0\"\n", 3, "winches.endpoint", "expected \"socketcan:<interface>"},
      {"[winches]\nendpoint = \"socketcan:\"\n", 3, "winches.endpoint", "or \"unix:<path>"},
      {"[winches]\nendpoint = \"socketcan:a-very-long-can-name\"\n", 3, "winches.endpoint", "not an endpoint"},
      {"[winches]\nendpoint = \"tcp:host:1\"\n", 3, "winches.endpoint", "not an endpoint"},
      {"[load_cell]\nendpoint = \"/dev/ttyUSB0\"\n", 3, "load_cell.endpoint", "\"tcp:<host>:<port>\" or \"rtu:"},
      {"[load_cell]\nendpoint = \"tcp:127.0.0.1\"\n", 3, "load_cell.endpoint", "not an endpoint"},
      {"[load_cell]\nendpoint = \"tcp:127.0.0.1:70000\"\n", 3, "load_cell.endpoint", "not an endpoint"},
      {"[load_cell]\nendpoint = \"rtu:\"\n", 3, "load_cell.endpoint", "not an endpoint"},
      {"[pose]\nendpoint = \"/run/pose.sock\"\n", 3, "pose.endpoint", "\"unix:<path>"},
      {"[pose]\nendpoint = \"tcp::5600\"\n", 3, "pose.endpoint", "not an endpoint"},
      {"[pose]\nendpoint = \"unix:/" + std::string(120, 'p') + "\"\n", 3, "pose.endpoint", "at most 107 bytes"},
      {"[control]\nsocket = \"/" + std::string(120, 's') + "\"\n", 3, "control.socket", "longer than"},
  };
  for (const Case& c : cases) expect_refused(c);
}

TEST(ConfigChecks, EndpointsOfEveryTransportAreAccepted) {
  // GIVEN each form every endpoint key takes WHEN parsed THEN accepted
  for (const std::string text :
       {"[winches]\nendpoint = \"socketcan:can0\"\n[load_cell]\nendpoint = \"rtu:/dev/ttyS0\"\n"
        "[pose]\nendpoint = \"unix:/run/pose.sock\"\n",
        "[winches]\nendpoint = \"unix:/run/can.sock\"\n[load_cell]\nendpoint = \"tcp:127.0.0.1:502\"\n"
        "[pose]\nendpoint = \"tcp:localization.local:5600\"\n"}) {
    const auto config = parse_daemon_config(test::config_text(text), "ok.toml");
    EXPECT_TRUE(config) << config.error().message();
  }
}

TEST(ConfigChecks, TheWorkspaceAndZBandMustFitTheRobot) {
  const Robot robot = cdpr::test::large_robot();  // anchors 240 m x 220 m, 50 m high
  // GIVEN a margin that eats the footprint, and a z band reaching the anchors
  const auto wide = parse_daemon_config(test::config_text("[waypoints]\nmargin = 130.0\n"), "m.toml");
  const auto high = parse_daemon_config(test::config_text("[waypoints]\nz_max = 55.0\n"), "z.toml");
  const auto fine = parse_daemon_config(test::config_text(""), "ok.toml");
  ASSERT_TRUE(wide && high && fine);
  // WHEN checked against the robot
  const auto no_workspace = check_config_against_robot(*wide, robot);
  const auto above = check_config_against_robot(*high, robot);
  // THEN both are refused naming the key and its line; the defaults suit the robot
  ASSERT_TRUE(no_workspace.has_value());
  EXPECT_EQ(no_workspace->message().substr(0, 25), "m.toml:3: waypoints.margi") << no_workspace->message();
  EXPECT_NE(no_workspace->message().find("no workspace"), std::string::npos) << no_workspace->message();
  ASSERT_TRUE(above.has_value());
  EXPECT_EQ(above->field, "waypoints.z_max");
  EXPECT_EQ(above->line, 3);
  EXPECT_NE(above->message().find("not below the lowest anchor"), std::string::npos) << above->message();
  EXPECT_FALSE(check_config_against_robot(*fine, robot).has_value());
}

}  // namespace
}  // namespace cdpr::daemon
