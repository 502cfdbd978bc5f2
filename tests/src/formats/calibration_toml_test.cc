#include "src/formats/calibration_toml.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "format_test_support.h"

namespace cdpr::formats {
namespace {

// The calibration.toml example of docs/FORMATS.md with a second winch and an
// [effects] table.
const std::string kExample = R"(format = 1
created = 2026-11-22T10:15:00Z
robot = "large"
model = ["catenary"]               # the model terms that were fitted, e.g. ["catenary", "elasticity"]
samples = 35

[[winch]]                          # in cable order
anchor = [0.12, -0.03, 49.97]      # m, world frame (estimated)
anchor_sigma = [0.02, 0.02, 0.05]  # m, 1-sigma from the fit's covariance
offset = 3.214                     # m
offset_sigma = 0.03                # m

[[winch]]
anchor = [200.1, 0.2, 50.01]
anchor_sigma = [0.03, 0.02, 0.04]
offset = -1.5
offset_sigma = 0.02

[fit]
cost_initial = 1.2e6
cost_final = 30.1
iterations = 14
rms_encoder = 0.009                # m
rms_force = 4.8                    # N

# [effects] holds the fitted parameters of any extra model terms, by name,
# e.g. axial_stiffness = 1.9e6, encoder_scale = [...], force_bias = 1.2
[effects]
axial_stiffness = 1.9e6
encoder_scale = [1e-4, -2e-4, 0, 3]
)";

using test::BadEdit;

std::string example_with(const std::string& from, const std::string& to) { return test::replaced(kExample, from, to); }

FormatError parse_error(const std::string& text) {
  const auto calibration = parse_calibration_toml(text, "calibration.toml");
  EXPECT_FALSE(calibration.has_value());
  return calibration ? FormatError{} : calibration.error();
}

TEST(CalibrationToml, ExampleOfFormatsMdParses) {
  // GIVEN the documented example
  // WHEN it is parsed
  const auto calibration = parse_calibration_toml(kExample, "calibration.toml");
  // THEN every value arrives, the date-time as its RFC 3339 text
  ASSERT_TRUE(calibration.has_value()) << calibration.error().message();
  EXPECT_EQ(calibration->format, 1);
  EXPECT_EQ(calibration->created, "2026-11-22T10:15:00Z");
  EXPECT_EQ(calibration->robot, "large");
  EXPECT_EQ(calibration->model, std::vector<std::string>{"catenary"});
  EXPECT_EQ(calibration->samples, 35);
  ASSERT_EQ(calibration->winches.size(), 2u);
  EXPECT_EQ(calibration->winches[0].anchor_world, Eigen::Vector3d(0.12, -0.03, 49.97));
  EXPECT_EQ(calibration->winches[0].anchor_sigma, Eigen::Vector3d(0.02, 0.02, 0.05));
  EXPECT_EQ(calibration->winches[0].offset_m, 3.214);
  EXPECT_EQ(calibration->winches[1].offset_sigma_m, 0.02);
  EXPECT_EQ(calibration->fit.cost_initial, 1.2e6);
  EXPECT_EQ(calibration->fit.cost_final, 30.1);
  EXPECT_EQ(calibration->fit.iterations, 14);
  EXPECT_EQ(calibration->fit.rms_encoder_m, 0.009);
  EXPECT_EQ(calibration->fit.rms_force_n, 4.8);
  EXPECT_EQ(calibration->effects.at("axial_stiffness"), std::vector<double>{1.9e6});
  EXPECT_EQ(calibration->effects.at("encoder_scale"), (std::vector<double>{1e-4, -2e-4, 0.0, 3.0}));
}

TEST(CalibrationToml, OtherZonesAndFractionsKeepTheirRfc3339Form) {
  // GIVEN a time with an offset and fractional seconds
  const std::string text = example_with("2026-11-22T10:15:00Z", "2026-11-22T11:15:00.25+01:00");
  // WHEN it is parsed
  const auto calibration = parse_calibration_toml(text, "calibration.toml");
  // THEN the string keeps both
  ASSERT_TRUE(calibration.has_value()) << calibration.error().message();
  EXPECT_EQ(calibration->created, "2026-11-22T11:15:00.25+01:00");
}

class CalibrationTomlBadInput : public testing::TestWithParam<BadEdit> {};

TEST_P(CalibrationTomlBadInput, IsRefusedWithKeyAndReason) {
  // GIVEN the example with one thing spoilt
  const BadEdit& bad = GetParam();
  const std::string text = example_with(bad.from, bad.to);
  // WHEN it is parsed
  const FormatError error = parse_error(text);
  // THEN the error names the key, the line of the spoilt value and why
  test::expect_refusal(error, bad, text);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CalibrationTomlBadInput,
    testing::Values(BadEdit{"newer format", "format = 1", "format = 2", "format",
                            "unsupported format version 2; this build reads version 1"},
                    BadEdit{"format as text", "format = 1", "format = \"1\"", "format", "expected an integer"},
                    BadEdit{"no format", "format = 1", "", "format", "missing required key", 0},
                    BadEdit{"created as string", "created = 2026-11-22T10:15:00Z", "created = \"2026-11-22T10:15:00Z\"",
                            "created", "expected an offset date-time like 2026-11-22T10:15:00Z, got a string"},
                    BadEdit{"created without zone", "10:15:00Z", "10:15:00", "created", "without offset"},
                    BadEdit{"model not strings", "[\"catenary\"]", "[1]", "model", "expected an array of strings"},
                    BadEdit{"negative samples", "samples = 35", "samples = -1", "samples", "must be a count >= 0"},
                    BadEdit{"negative sigma", "offset_sigma = 0.03", "offset_sigma = -0.03", "winch[0].offset_sigma",
                            "must be >= 0"},
                    BadEdit{"unknown winch key", "offset = -1.5", "ofset = -1.5", "winch[1].ofset",
                            "did you mean 'offset'?"},
                    BadEdit{"missing fit key", "iterations = 14", "", "fit.iterations", "missing required key", 19},
                    BadEdit{"effect not numeric", "\naxial_stiffness = 1.9e6", "\naxial_stiffness = \"big\"",
                            "effects.axial_stiffness", "expected a number or an array of numbers"},
                    BadEdit{"effect with nan", "0, 3]", "nan, 3]", "effects.encoder_scale[2]", "finite"},
                    BadEdit{"empty effect", "[1e-4, -2e-4, 0, 3]", "[]", "effects.encoder_scale", "non-empty"}),
    test::case_name);

TEST(CalibrationToml, FormatThenParseGivesTheSameCalibration) {
  // GIVEN a calibration with values that need all 17 digits
  const auto parsed = parse_calibration_toml(kExample, "calibration.toml");
  ASSERT_TRUE(parsed.has_value());
  Calibration calibration = *parsed;
  calibration.model = {"catenary", "elasticity", "swivel \"pulley\""};
  calibration.winches[1].anchor_world = Eigen::Vector3d(1.0 / 3.0, -2.0 / 7.0, 50.000000000000007);
  calibration.winches[1].offset_sigma_m = std::sqrt(2e-5);
  calibration.fit.cost_final = 0.1 + 0.2;
  calibration.effects["force_bias"] = {-1.0 / 9.0};
  calibration.effects["weird name"] = {1.0, 2.0};
  calibration.rejected = {{12, SensorKind::kEncoder, 3, 87.25},
                          {30, SensorKind::kForce, 0, -12.5, 1},
                          {30, SensorKind::kEncoder, 2, 6.5, 1}};
  calibration.model_warning = "the residuals are 3.1 times the noise";
  // WHEN it is formatted and parsed again
  const std::string text = format_calibration_toml(calibration);
  const auto again = parse_calibration_toml(text, "written.toml");
  // THEN every field is bit-identical
  ASSERT_TRUE(again.has_value()) << again.error().message() << "\n" << text;
  EXPECT_EQ(again->format, calibration.format);
  EXPECT_EQ(again->created, calibration.created);
  EXPECT_EQ(again->robot, calibration.robot);
  EXPECT_EQ(again->model, calibration.model);
  EXPECT_EQ(again->samples, calibration.samples);
  ASSERT_EQ(again->winches.size(), calibration.winches.size());
  for (std::size_t i = 0; i < calibration.winches.size(); ++i) {
    EXPECT_EQ(again->winches[i].anchor_world, calibration.winches[i].anchor_world);
    EXPECT_EQ(again->winches[i].anchor_sigma, calibration.winches[i].anchor_sigma);
    EXPECT_EQ(again->winches[i].offset_m, calibration.winches[i].offset_m);
    EXPECT_EQ(again->winches[i].offset_sigma_m, calibration.winches[i].offset_sigma_m);
  }
  EXPECT_EQ(again->fit.cost_initial, calibration.fit.cost_initial);
  EXPECT_EQ(again->fit.cost_final, calibration.fit.cost_final);
  EXPECT_EQ(again->fit.iterations, calibration.fit.iterations);
  EXPECT_EQ(again->fit.rms_encoder_m, calibration.fit.rms_encoder_m);
  EXPECT_EQ(again->fit.rms_force_n, calibration.fit.rms_force_n);
  EXPECT_EQ(again->effects, calibration.effects);
  EXPECT_EQ(again->model_warning, calibration.model_warning);
  ASSERT_EQ(again->rejected.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(again->rejected[k].row, calibration.rejected[k].row);
    EXPECT_EQ(again->rejected[k].sensor, calibration.rejected[k].sensor);
    EXPECT_EQ(again->rejected[k].cable, calibration.rejected[k].cable);
    EXPECT_EQ(again->rejected[k].value, calibration.rejected[k].value);
    EXPECT_EQ(again->rejected[k].group, calibration.rejected[k].group);
  }
}

TEST(CalibrationToml, FormatWithoutEffectsHasNoEffectsTable) {
  // GIVEN a calibration without effects
  auto calibration = parse_calibration_toml(kExample, "calibration.toml");
  ASSERT_TRUE(calibration.has_value());
  calibration->effects.clear();
  // WHEN it is formatted
  const std::string text = format_calibration_toml(*calibration);
  // THEN there is no [effects] table and it still reads back
  EXPECT_EQ(text.find("[effects]"), std::string::npos);
  const auto again = parse_calibration_toml(text, "written.toml");
  ASSERT_TRUE(again.has_value()) << again.error().message();
  EXPECT_TRUE(again->effects.empty());
}

TEST(CalibrationToml, EmptyModelListRoundTrips) {
  // GIVEN a calibration that lists no model terms
  auto calibration = parse_calibration_toml(kExample, "calibration.toml");
  ASSERT_TRUE(calibration.has_value());
  calibration->model.clear();
  // WHEN it is formatted and parsed again
  const auto again = parse_calibration_toml(format_calibration_toml(*calibration), "written.toml");
  // THEN the list is still empty
  ASSERT_TRUE(again.has_value()) << again.error().message();
  EXPECT_TRUE(again->model.empty());
}

TEST(CalibrationToml, TheDaemonsRunSummaryRoundTripsAndOldFilesHaveNone) {
  // GIVEN a file without [run] (older files, offline fits)
  auto calibration = parse_calibration_toml(kExample, "calibration.toml");
  ASSERT_TRUE(calibration.has_value());
  // THEN it reads, with no run summary, and is written without one
  EXPECT_FALSE(calibration->run.has_value());
  EXPECT_EQ(format_calibration_toml(*calibration).find("[run]"), std::string::npos);
  // GIVEN the daemon's run summary WHEN formatted and parsed again THEN it is the same
  calibration->run = RunSummary{412.5 + 1.0 / 3.0, 19, "sequential", "target reached"};
  const std::string text = format_calibration_toml(*calibration);
  const auto again = parse_calibration_toml(text, "written.toml");
  ASSERT_TRUE(again.has_value()) << again.error().message() << "\n" << text;
  ASSERT_TRUE(again->run.has_value());
  EXPECT_EQ(again->run->robot_time_s, calibration->run->robot_time_s);
  EXPECT_EQ(again->run->waypoints, 19);
  EXPECT_EQ(again->run->strategy, "sequential");
  EXPECT_EQ(again->run->stop, "target reached");
  // AND a [run] missing a key is refused naming it
  const auto partial = parse_calibration_toml(test::replaced(text, "stop = ", "stopped = "), "partial.toml");
  ASSERT_FALSE(partial.has_value());
  EXPECT_NE(partial.error().message().find("run."), std::string::npos) << partial.error().message();
}

TEST(CalibrationTomlDeathTest, FormatRefusesACreatedThatIsNoDateTime) {
  // GIVEN a calibration whose `created` is not a date-time
  Calibration calibration;
  calibration.created = "yesterday";
  // WHEN it is formatted THEN the broken invariant stops the program
  EXPECT_DEATH((void)format_calibration_toml(calibration), "not an RFC 3339 date-time");
}

}  // namespace
}  // namespace cdpr::formats
