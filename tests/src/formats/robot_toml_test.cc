#include "src/formats/robot_toml.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "format_test_support.h"

namespace cdpr::formats {
namespace {

// The robot.toml example of docs/FORMATS.md, verbatim but for three more winches
// (the solver needs four cables).
const std::string kRobotExample = R"(name = "large"                     # free text
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

using test::BadEdit;
using test::line_of;

std::string robot_example_with(const std::string& from, const std::string& to) { return test::replaced(kRobotExample, from, to); }

FormatError robot_parse_error(const std::string& text) {
  const auto robot = parse_robot_toml(text, "robot.toml");
  EXPECT_FALSE(robot.has_value());
  return robot ? FormatError{} : robot.error();
}

TEST(RobotToml, ExampleOfFormatsMdParses) {
  // GIVEN the documented example
  // WHEN it is parsed
  const auto robot = parse_robot_toml(kRobotExample, "robot.toml");
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
  const std::string text = robot_example_with("anchor = [200.0, 200.0, 50.0]", "ancor = [200.0, 200.0, 50.0]");
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN the error names the dotted key, its line and the key that was meant
  EXPECT_EQ(error.field, "winch[2].ancor");
  EXPECT_EQ(error.line, line_of(text, "ancor"));
  EXPECT_NE(error.reason.find("unknown key"), std::string::npos) << error.reason;
  EXPECT_NE(error.reason.find("'anchor'"), std::string::npos) << error.reason;
  EXPECT_EQ(error.message(), "robot.toml:" + std::to_string(error.line) + ": winch[2].ancor: " + error.reason);
}

TEST(RobotToml, MissingKeysAreAllNamed) {
  // GIVEN [platform] without mass and without center_of_mass
  std::string text = robot_example_with("mass = 34.0", "");
  text = text.replace(text.find("center_of_mass"), 14, "# center_of_ma");
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN both keys are named, at the line of their table
  EXPECT_EQ(error.field, "platform.mass, platform.center_of_mass");
  EXPECT_EQ(error.reason, "missing required keys");
  EXPECT_EQ(error.line, line_of(text, "[platform]"));
}

TEST(RobotToml, MissingTopLevelKeyConcernsTheWholeFile) {
  // GIVEN no name
  const std::string text = robot_example_with("name = \"large\"", "");
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN the key is named and no line is claimed
  EXPECT_EQ(error.message(), "robot.toml: name: missing required key");
}

TEST(RobotToml, MissingTableIsNamed) {
  // GIVEN no [noise] table at all
  const std::string text = kRobotExample.substr(0, kRobotExample.find("[noise]"));
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN the table is named as missing
  EXPECT_EQ(error.field, "noise");
  EXPECT_NE(error.reason.find("missing"), std::string::npos) << error.reason;
}

TEST(RobotToml, UnknownTableIsRefused) {
  // GIVEN a table this version does not know
  const std::string text = kRobotExample + "\n[limits]\nmax_tension = 3000.0\n";
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN it is named with its line
  EXPECT_EQ(error.field, "limits");
  EXPECT_EQ(error.line, line_of(text, "[limits]"));
  EXPECT_NE(error.reason.find("unknown table"), std::string::npos) << error.reason;
}

TEST(RobotToml, IntegersAreAcceptedForNumbers) {
  // GIVEN a mass and an anchor coordinate written as integers
  const std::string text = robot_example_with("mass = 34.0", "mass = 34");
  // WHEN it is parsed
  const auto robot = parse_robot_toml(text, "robot.toml");
  // THEN they read as the same numbers
  ASSERT_TRUE(robot.has_value()) << robot.error().message();
  EXPECT_EQ(robot->platform_mass_kg, 34.0);
}

TEST(RobotToml, IntegersBeyondDoublePrecisionAreStillNumbers) {
  // GIVEN an absurd but valid integer that a double cannot hold exactly (2^53 + 1)
  const std::string text = robot_example_with("mass = 34.0", "mass = 9007199254740993");
  // WHEN it is parsed
  const auto robot = parse_robot_toml(text, "robot.toml");
  // THEN it reads as the nearest double rather than as an error
  ASSERT_TRUE(robot.has_value()) << robot.error().message();
  EXPECT_EQ(robot->platform_mass_kg, 9007199254740992.0);
}

TEST(RobotToml, OptionalKeysHaveTheirDefaultsOrValues) {
  // GIVEN no gravity line and an axial stiffness
  std::string text = robot_example_with("gravity = 9.81 ", "# gravity");
  text = text.replace(text.find("# axial_stiffness"), 2, "");
  // WHEN it is parsed
  const auto robot = parse_robot_toml(text, "robot.toml");
  // THEN gravity is the documented default and EA is read
  ASSERT_TRUE(robot.has_value()) << robot.error().message();
  EXPECT_EQ(robot->gravity_mps2, 9.81);
  ASSERT_TRUE(robot->axial_stiffness_n.has_value());
  EXPECT_EQ(*robot->axial_stiffness_n, 2.0e6);
}

class RobotTomlBadValue : public testing::TestWithParam<BadEdit> {};

TEST_P(RobotTomlBadValue, IsRefusedWithLineKeyAndReason) {
  // GIVEN the example with one value spoilt
  const BadEdit& bad = GetParam();
  const std::string text = robot_example_with(bad.from, bad.to);
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN the error names the key, the line of the spoilt value and why
  test::expect_refusal(error, bad, text);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, RobotTomlBadValue,
    testing::Values(
        BadEdit{"negative mass", "mass = 34.0", "mass = -34.0", "platform.mass", "must be > 0, got -34"},
        BadEdit{"zero density", "linear_density = 0.0724", "linear_density = 0", "cable.linear_density", "must be > 0"},
        BadEdit{"zero sigma", "force = 5.0", "force = 0.0", "noise.force", "must be > 0"},
        BadEdit{"nan gravity", "gravity = 9.81", "gravity = nan", "gravity", "finite"},
        BadEdit{"inf anchor", "anchor = [0.0, 0.0, 50.0]", "anchor = [0.0, inf, 50.0]", "winch[0].anchor[1]", "finite"},
        BadEdit{"non-numeric", "mass = 34.0", "mass = \"heavy\"", "platform.mass", "expected a number, got a string"},
        BadEdit{"short array", "center_of_mass = [0.0, 0.0, 0.0]", "center_of_mass = [0.0, 0.0]",
                "platform.center_of_mass", "expected an array of 3 numbers [x, y, z], got an array of 2"},
        BadEdit{"long array", "attachment = [-0.1, 0.1, 0.0]", "attachment = [-0.1, 0.1, 0.0, 1.0]",
                "winch[1].attachment", "got an array of 4"},
        BadEdit{"scalar for array", "anchor = [200.0, 0.0, 50.0]", "anchor = 200.0", "winch[1].anchor", "got a number"},
        BadEdit{"string in array", "anchor = [0.0, 200.0, 50.0]", "anchor = [0.0, \"200\", 50.0]", "winch[3].anchor[1]",
                "expected a number"},
        BadEdit{"reference past the end", "reference = 0", "reference = 4", "cable.reference",
                "cable index 4 does not exist; cables are numbered 0..3"},
        BadEdit{"negative reference", "reference = 0", "reference = -1", "cable.reference", "cable index -1"},
        BadEdit{"fractional reference", "reference = 0", "reference = 0.5", "cable.reference", "expected an integer"},
        BadEdit{"name not text", "name = \"large\"", "name = 7", "name", "expected a string"}),
    test::case_name);

TEST(RobotToml, WrongWinchCountIsRefusedWithTheCount) {
  // GIVEN only three [[winch]] tables
  const std::size_t last = kRobotExample.rfind("[[winch]]");
  const std::string text = kRobotExample.substr(0, last) + kRobotExample.substr(kRobotExample.find("[noise]"));
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN the error says how many were found and how many are needed
  EXPECT_EQ(error.field, "winch");
  EXPECT_NE(error.reason.find("found 3 [[winch]] tables"), std::string::npos) << error.reason;
  EXPECT_NE(error.reason.find("exactly 4"), std::string::npos) << error.reason;
}

TEST(RobotToml, SingleWinchIsNotACableRobot) {
  // GIVEN one [[winch]] table
  const std::size_t second = kRobotExample.find("[[winch]]", kRobotExample.find("[[winch]]") + 1);
  const std::string text = kRobotExample.substr(0, second) + kRobotExample.substr(kRobotExample.find("[noise]"));
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN the error says at least two are needed
  EXPECT_NE(error.reason.find("at least 2"), std::string::npos) << error.reason;
}

TEST(RobotToml, SyntaxErrorKeepsTomlsLine) {
  // GIVEN a line that is not TOML
  const std::string text = robot_example_with("mass = 34.0", "mass = = 34.0");
  // WHEN it is parsed
  const FormatError error = robot_parse_error(text);
  // THEN the error carries that line and the parser's description
  EXPECT_EQ(error.line, line_of(text, "mass = ="));
  EXPECT_NE(error.reason.find("TOML syntax"), std::string::npos) << error.reason;
}

TEST(RobotToml, FormatThenParseGivesTheSameRobot) {
  // GIVEN a robot with values that need all 17 digits, with and without EA
  const auto parsed = parse_robot_toml(kRobotExample, "robot.toml");
  ASSERT_TRUE(parsed.has_value());
  Robot robot = *parsed;
  robot.name = "odd \"name\" \\ with\ttab";
  robot.gravity_mps2 = 9.80665;
  robot.platform_mass_kg = 0.1 + 0.2;
  robot.center_of_mass_platform = Eigen::Vector3d(1.0 / 3.0, -2e-17, 1e20);
  robot.cable_linear_density_kgpm = std::nextafter(0.0724, 1.0);
  robot.reference_cable = 2;
  robot.winches[1].anchor_world = Eigen::Vector3d(200.123456789012345, -0.0, 49.999999999999993);
  robot.noise.orientation_rad = 1.0 / 7.0;
  for (const std::optional<double> stiffness : {std::optional<double>(), std::optional<double>(1.9e6 / 3.0)}) {
    robot.axial_stiffness_n = stiffness;
    // WHEN it is formatted and parsed again
    const std::string text = format_robot_toml(robot);
    const auto again = parse_robot_toml(text, "written.toml");
    // THEN every field is bit-identical
    ASSERT_TRUE(again.has_value()) << again.error().message() << "\n" << text;
    EXPECT_EQ(again->name, robot.name);
    EXPECT_EQ(again->gravity_mps2, robot.gravity_mps2);
    EXPECT_EQ(again->platform_mass_kg, robot.platform_mass_kg);
    EXPECT_EQ(again->center_of_mass_platform, robot.center_of_mass_platform);
    EXPECT_EQ(again->cable_linear_density_kgpm, robot.cable_linear_density_kgpm);
    EXPECT_EQ(again->reference_cable, robot.reference_cable);
    EXPECT_EQ(again->axial_stiffness_n, robot.axial_stiffness_n);
    ASSERT_EQ(again->cable_count(), robot.cable_count());
    for (int i = 0; i < robot.cable_count(); ++i) {
      EXPECT_EQ(again->winches[i].anchor_world, robot.winches[i].anchor_world) << i;
      EXPECT_EQ(again->winches[i].attachment_platform, robot.winches[i].attachment_platform) << i;
    }
    EXPECT_EQ(again->noise.encoder_m, robot.noise.encoder_m);
    EXPECT_EQ(again->noise.force_n, robot.noise.force_n);
    EXPECT_EQ(again->noise.position_m, robot.noise.position_m);
    EXPECT_EQ(again->noise.orientation_rad, robot.noise.orientation_rad);
  }
}

TEST(RobotToml, MissingFileNamesPathAndReason) {
  // GIVEN a path that does not exist
  const std::string path = std::string(CDPR_BINARY_DIR) + "/no/such/robot.toml";
  // WHEN it is read
  const auto robot = read_robot_toml(path);
  // THEN the error names the path and the system's reason
  ASSERT_FALSE(robot.has_value());
  EXPECT_EQ(robot.error().file, path);
  EXPECT_NE(robot.error().message().find("No such file"), std::string::npos) << robot.error().message();
}

}  // namespace
}  // namespace cdpr::formats
