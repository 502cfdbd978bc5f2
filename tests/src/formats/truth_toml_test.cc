#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"

namespace cdpr::formats {
namespace {

// The truth.toml example of docs/FORMATS.md with its effect uncommented and a second winch.
const std::string kTruthExample = R"([[winch]]
anchor = [0.0, 0.0, 50.0]          # m, true pulley exit point
offset = 3.2                       # m, true encoder offset

[[winch]]
anchor = [200.0, 0.0, 50.0]
offset = -0.7

[effects]                          # effects present in the data, with their true values
axial_stiffness = 1.5e6
)";

TEST(TruthToml, ExampleOfFormatsMdParses) {
  // GIVEN the documented example
  // WHEN it is parsed
  const auto truth = parse_truth_toml(kTruthExample, "truth.toml");
  // THEN winches and effects arrive
  ASSERT_TRUE(truth.has_value()) << truth.error().message();
  ASSERT_EQ(truth->winches.size(), 2u);
  EXPECT_EQ(truth->winches[0].anchor_world, Eigen::Vector3d(0.0, 0.0, 50.0));
  EXPECT_EQ(truth->winches[0].offset_m, 3.2);
  EXPECT_EQ(truth->winches[1].offset_m, -0.7);
  EXPECT_EQ(truth->effects.at("axial_stiffness"), std::vector<double>{1.5e6});
}

TEST(TruthToml, EffectsAreOptional) {
  // GIVEN no [effects] table
  const std::string text = kTruthExample.substr(0, kTruthExample.find("[effects]"));
  // WHEN it is parsed
  const auto truth = parse_truth_toml(text, "truth.toml");
  // THEN there are no effects
  ASSERT_TRUE(truth.has_value()) << truth.error().message();
  EXPECT_TRUE(truth->effects.empty());
}

TEST(TruthToml, UnknownKeyIsNamedWithItsLine) {
  // GIVEN a key truth.toml does not have
  const std::string text = kTruthExample + "[noise]\nencoder = 0.01\n";
  // WHEN it is parsed
  const auto truth = parse_truth_toml(text, "truth.toml");
  // THEN it is refused with its name and line
  ASSERT_FALSE(truth.has_value());
  EXPECT_EQ(truth.error().field, "noise");
  EXPECT_EQ(truth.error().line, 11);  // the line after the example's 10
}

TEST(TruthToml, NonNumericEffectIsKeptAsNotCompared) {
  // GIVEN an [effects] key with a boolean and one with a string (evaluation
  // input from another simulator)
  const std::string text = kTruthExample + "massless = true\nsource = \"fem\"\n";
  // WHEN it is parsed
  const auto truth = parse_truth_toml(text, "truth.toml");
  // THEN it is read, the numeric effect compared, the others named as not compared
  ASSERT_TRUE(truth.has_value()) << truth.error().message();
  EXPECT_EQ(truth->effects.size(), 1u);
  EXPECT_EQ(truth->uncompared_effects, (std::vector<std::string>{"massless", "source"}));
}

TEST(TruthToml, PlantedOutliersRoundTrip) {
  // GIVEN a truth with two planted gross errors
  auto truth = parse_truth_toml(kTruthExample, "truth.toml");
  ASSERT_TRUE(truth.has_value());
  truth->outliers = {{3, SensorKind::kEncoder, 2, -1.25}, {7, SensorKind::kForce, 0, 312.5}};
  // WHEN it is formatted and parsed again
  const auto again = parse_truth_toml(format_truth_toml(*truth), "again.toml");
  // THEN the rows, sensors, cables and errors come back
  ASSERT_TRUE(again.has_value()) << again.error().message();
  ASSERT_EQ(again->outliers.size(), 2u);
  EXPECT_EQ(again->outliers[0].row, 3);
  EXPECT_EQ(again->outliers[0].sensor, SensorKind::kEncoder);
  EXPECT_EQ(again->outliers[0].cable, 2);
  EXPECT_EQ(again->outliers[0].value, -1.25);
  EXPECT_EQ(again->outliers[1].sensor, SensorKind::kForce);
  EXPECT_EQ(again->outliers[1].value, 312.5);
}

TEST(TruthToml, OutlierWithUnknownSensorIsRefused) {
  const std::string text = kTruthExample + "\n[[outlier]]\nrow = 1\nsensor = \"pose\"\ncable = 0\nerror = 1.0\n";
  const auto truth = parse_truth_toml(text, "truth.toml");
  ASSERT_FALSE(truth.has_value());
  EXPECT_EQ(truth.error().field, "outlier[0].sensor");
}

TEST(TruthToml, MissingWinchesAreRefused) {
  // GIVEN only effects
  // WHEN it is parsed
  const auto truth = parse_truth_toml("[effects]\nforce_bias = 1.0\n", "truth.toml");
  // THEN the missing winches are named
  ASSERT_FALSE(truth.has_value());
  EXPECT_EQ(truth.error().message(), "truth.toml: winch: missing required key");
}

TEST(TruthToml, FormatThenParseGivesTheSameTruth) {
  // GIVEN a truth with full-precision values and scalar and per-cable effects
  Truth truth;
  for (int i = 0; i < 4; ++i) {
    truth.winches.push_back({Eigen::Vector3d(std::sqrt(2.0) * i, -1.0 / (i + 3.0), 50.0 + 0.1 * i), 0.3 * i - 0.1});
  }
  truth.effects["axial_stiffness"] = {1.5e6 / 7.0};
  truth.effects["encoder_scale"] = {1e-4, -3e-5, 0.0, 2.5e-4};
  // WHEN it is formatted and parsed again
  const std::string text = format_truth_toml(truth);
  const auto again = parse_truth_toml(text, "written.toml");
  // THEN every value is bit-identical
  ASSERT_TRUE(again.has_value()) << again.error().message() << "\n" << text;
  ASSERT_EQ(again->winches.size(), truth.winches.size());
  for (std::size_t i = 0; i < truth.winches.size(); ++i) {
    EXPECT_EQ(again->winches[i].anchor_world, truth.winches[i].anchor_world);
    EXPECT_EQ(again->winches[i].offset_m, truth.winches[i].offset_m);
  }
  EXPECT_EQ(again->effects, truth.effects);
}

}  // namespace
}  // namespace cdpr::formats
