#include <gtest/gtest.h>

#include "src/control/control_request.h"

namespace cdpr::control {
namespace {

TEST(StartWaypointsRequest, NamesTheFileAndOptionallyTheRunToAppendTo) {
  // GIVEN start requests with a waypoints file, with and without a run
  const auto alone = parse_request("start waypoints /var/tmp/d/waypoints.csv\n");
  const auto appended = parse_request("start  waypoints\t/var/tmp/w.csv run-000007");
  const auto numbered = parse_request("start waypoints /w.csv 7");
  // THEN the path is passed on as given and the run as its number (0: none)
  ASSERT_TRUE(alone && appended && numbered);
  EXPECT_EQ(alone->kind, RequestKind::kStart);
  EXPECT_EQ(alone->waypoints_path, "/var/tmp/d/waypoints.csv");
  EXPECT_EQ(alone->run, 0);
  EXPECT_EQ(appended->waypoints_path, "/var/tmp/w.csv");
  EXPECT_EQ(appended->run, 7);
  EXPECT_EQ(numbered->run, 7);
  // AND a plain start stays a plain start
  EXPECT_TRUE(parse_request("start")->waypoints_path.empty());
}

TEST(StartWaypointsRequest, MistakesAreRefusedWithAReason) {
  // GIVEN malformed start requests WHEN parsed THEN each error says what is wrong
  const std::string usage = "start takes no argument or: waypoints <path> [<run>]";
  EXPECT_EQ(parse_request("start waypoints").error(), usage);
  EXPECT_EQ(parse_request("start points /w.csv").error(), usage);
  EXPECT_EQ(parse_request("start waypoints /w.csv 7 8").error(), usage);
  EXPECT_EQ(parse_request("start waypoints w.csv").error(), "waypoints path 'w.csv' is not absolute");
  EXPECT_EQ(parse_request("start waypoints /w.csv 0").error(), "run '0' is not a run number (7 or run-000007)");
  EXPECT_EQ(parse_request("start waypoints /w.csv run-x").error(), "run 'run-x' is not a run number (7 or run-000007)");
}

}  // namespace
}  // namespace cdpr::control
