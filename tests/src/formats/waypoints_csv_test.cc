#include "src/formats/waypoints_csv.h"

#include <string>

#include <gtest/gtest.h>

namespace cdpr::formats {
namespace {

// The waypoints.csv example of docs/FORMATS.md.
const std::string kWaypointsExample =
    "# waypoints that tell the mimicking terms apart (cdpr-calib diagnose samples.csv)\n"
    "x,y,z,separation_sigma\n"
    "120,20,35,4.41\n"
    "20,110,35,3.8\n";

FormatError waypoints_error(const std::string& text) {
  const auto waypoints = parse_waypoints_csv(text, "waypoints.csv");
  EXPECT_FALSE(waypoints.has_value());
  return waypoints ? FormatError{} : waypoints.error();
}

TEST(WaypointsCsv, ExampleOfFormatsMdParsesAndFormatsBack) {
  const auto waypoints = parse_waypoints_csv(kWaypointsExample, "waypoints.csv");
  ASSERT_TRUE(waypoints) << waypoints.error().message();
  ASSERT_EQ(waypoints->size(), 2u);
  EXPECT_EQ((*waypoints)[1].position_world, Eigen::Vector3d(20.0, 110.0, 35.0));
  EXPECT_EQ((*waypoints)[0].separation_sigma, 4.41);
  const std::string text =
      format_waypoints_csv(*waypoints, "waypoints that tell the mimicking terms apart (cdpr-calib diagnose samples.csv)");
  EXPECT_EQ(text, kWaypointsExample);
}

TEST(WaypointsCsv, ThePositionsAloneAreEnough) {
  const auto waypoints = parse_waypoints_csv("x,y,z\r\n1.5,2,-30\r\n\r\n", "w.csv");
  ASSERT_TRUE(waypoints) << waypoints.error().message();
  ASSERT_EQ(waypoints->size(), 1u);
  EXPECT_EQ((*waypoints)[0].separation_sigma, 0.0);
}

TEST(WaypointsCsv, RefusalsNameTheLineAndTheColumn) {
  FormatError e = waypoints_error("x,y,z\n1,2,nan\n");
  EXPECT_EQ(e.line, 2);
  EXPECT_EQ(e.field, "z");
  e = waypoints_error("x,z,y\n1,2,3\n");
  EXPECT_EQ(e.line, 1);
  EXPECT_EQ(e.field, "z");
  e = waypoints_error("x,y,z\n1,2\n");
  EXPECT_EQ(e.line, 2);
  EXPECT_NE(e.reason.find("2 values"), std::string::npos) << e.reason;
  e = waypoints_error("x,y,z,separation_sigma\n1,2,3,-1\n");
  EXPECT_EQ(e.field, "separation_sigma");
  e = waypoints_error("x,y,z\n");
  EXPECT_NE(e.reason.find("no waypoint rows"), std::string::npos) << e.reason;
  e = waypoints_error("");
  EXPECT_NE(e.reason.find("no header"), std::string::npos) << e.reason;
}

}  // namespace
}  // namespace cdpr::formats
