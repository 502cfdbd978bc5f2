#include "src/formats/robot_toml.h"

#include <algorithm>
#include <string>

#include <gtest/gtest.h>

namespace cdpr::formats {
namespace {

// The robot.toml example of FORMATS.md, verbatim but for three more winches
// (the solver needs four cables).
const std::string kExample = R"(name = "large"                     # free text
gravity = 9.81                     # m/s^2, optional, default 9.81

[platform]
mass = 34.0                        # kg
center_of_mass = [0.0, 0.0, 0.0]   # m, platform frame (nominal)

[cable]
linear_density = 0.0724            # kg/m  (mass per unit length)
reference = 0                      # index of the cable whose tension the load cell measures
# axial_stiffness = 2.0e6          # EA in N; optional nominal value, absent = unknown/inextensible

[[winch]]                          # one table per cable, in cable order
anchor = [0.0, 0.0, 50.0]          # m, world frame: NOMINAL pulley exit point (an initial guess only)
attachment = [0.1, 0.1, 0.0]       # m, platform frame: cable attachment point (known)

[[winch]]
anchor = [200.0, 0.0, 50.0]
attachment = [-0.1, 0.1, 0.0]

[[winch]]
anchor = [200.0, 200.0, 50.0]
attachment = [-0.1, -0.1, 0.0]

[[winch]]
anchor = [0.0, 200.0, 50.0]
attachment = [0.1, -0.1, 0.0]

[noise]                            # 1-sigma sensor noise, used to weight the fit
encoder = 0.010                    # m
force = 5.0                        # N
position = 0.005                   # m   (pose translation)
orientation = 0.01                 # rad (pose rotation)
)";

// kExample with the first occurrence of `from` replaced by `to`.
std::string example_with(const std::string& from, const std::string& to) {
  std::string text = kExample;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// 1-based line of the first occurrence of `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  EXPECT_NE(at, std::string::npos) << needle;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(at), '\n'));
}

FormatError parse_error(const std::string& text) {
  const auto robot = parse_robot_toml(text, "robot.toml");
  EXPECT_FALSE(robot.has_value());
  return robot ? FormatError{} : robot.error();
}

TEST(RobotToml, ExampleOfFormatsMdParses) {
  // GIVEN the documented example
  // WHEN it is parsed
  const auto robot = parse_robot_toml(kExample, "robot.toml");
  // THEN every documented value arrives in the Robot
  ASSERT_TRUE(robot.has_value()) << robot.error().message();
  EXPECT_EQ(robot->name, "large");
  EXPECT_EQ(robot->gravity_mps2, 9.81);
  EXPECT_EQ(robot->platform_mass_kg, 34.0);
  EXPECT_EQ(robot->center_of_mass_platform, Eigen::Vector3d::Zero());
  EXPECT_EQ(robot->cable_linear_density_kgpm, 0.0724);
  EXPECT_EQ(robot->reference_cable, 0);
  EXPECT_FALSE(robot->axial_stiffness_n.has_value());
  ASSERT_EQ(robot->cable_count(), 4);
  EXPECT_EQ(robot->winches[0].anchor_world, Eigen::Vector3d(0.0, 0.0, 50.0));
  EXPECT_EQ(robot->winches[2].anchor_world, Eigen::Vector3d(200.0, 200.0, 50.0));
  EXPECT_EQ(robot->winches[3].attachment_platform, Eigen::Vector3d(0.1, -0.1, 0.0));
  EXPECT_EQ(robot->noise.encoder_m, 0.010);
  EXPECT_EQ(robot->noise.force_n, 5.0);
  EXPECT_EQ(robot->noise.position_m, 0.005);
  EXPECT_EQ(robot->noise.orientation_rad, 0.01);
}

TEST(RobotToml, UnknownKeyIsNamedWithItsLineAndASuggestion) {
  // GIVEN a misspelt key in the third winch table
  const std::string text = example_with("anchor = [200.0, 200.0, 50.0]", "ancor = [200.0, 200.0, 50.0]");
  // WHEN it is parsed
  const FormatError error = parse_error(text);
  // THEN the error names the dotted key, its line and the key that was meant
  EXPECT_EQ(error.field, "winch[2].ancor");
  EXPECT_EQ(error.line, line_of(text, "ancor"));
  EXPECT_NE(error.reason.find("unknown key"), std::string::npos) << error.reason;
  EXPECT_NE(error.reason.find("'anchor'"), std::string::npos) << error.reason;
  EXPECT_EQ(error.message(), "robot.toml:" + std::to_string(error.line) + ": winch[2].ancor: " + error.reason);
}

}  // namespace
}  // namespace cdpr::formats
