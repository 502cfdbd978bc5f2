// Every parser of outside input must survive any damage to its input: no
// crash, no exception, either a value or an error that says where and why.
// A deterministic companion of the fuzz targets in tests/fuzz/.

#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::formats {
namespace {

// Valid files to damage: what the formatters write.
Robot some_robot() {
  Robot robot;
  robot.name = "fuzz";
  robot.platform_mass_kg = 34.0;
  robot.cable_linear_density_kgpm = 0.0724;
  robot.axial_stiffness_n = 2.0e6;
  for (int i = 0; i < kCableCount; ++i) {
    robot.winches.push_back({Eigen::Vector3d(200.0 * (i % 2), 200.0 * (i / 2), 50.0), Eigen::Vector3d(0.1, -0.1, 0)});
  }
  return robot;
}

Calibration some_calibration() {
  Calibration calibration;
  calibration.created = "2026-11-22T10:15:00Z";
  calibration.robot = "fuzz";
  calibration.samples = 35;
  calibration.winches.resize(kCableCount);
  calibration.effects["encoder_scale"] = {1e-4, 2e-4, 3e-4, 4e-4};
  calibration.effects["axial_stiffness"] = {1.9e6};
  return calibration;
}

std::vector<Sample> some_samples() {
  std::vector<Sample> samples(3);
  for (int k = 0; k < 3; ++k) samples[k].id = k;
  return samples;
}

// One random edit: delete, duplicate, overwrite or insert a few bytes,
// mostly with characters that mean something to TOML or CSV.
std::string damaged(std::string text, std::mt19937& random) {
  static const std::string kAlphabet = "[]{}=,.\"'#\n\r \t0123456789eE+-_abnfitxz\\";
  const int edits = 1 + static_cast<int>(random() % 3);
  for (int e = 0; e < edits && !text.empty(); ++e) {
    const std::size_t at = random() % text.size();
    const std::size_t length = 1 + random() % 8;
    const char c = kAlphabet[random() % kAlphabet.size()];
    switch (random() % 4) {
      case 0: text.erase(at, length); break;
      case 1: text.insert(at, text.substr(at, length)); break;
      case 2: text[at] = c; break;
      default: text.insert(at, 1, c); break;
    }
  }
  return text;
}

template <class Parse>
void expect_survives_damage(const std::string& valid, Parse parse) {
  std::mt19937 random(12345);
  int refused = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const std::string text = damaged(valid, random);
    const auto result = parse(text);
    if (result.has_value()) continue;
    ++refused;
    EXPECT_EQ(result.error().file, "damaged") << text;
    EXPECT_FALSE(result.error().reason.empty()) << text;
    EXPECT_GE(result.error().line, 0) << text;
  }
  // (the damage must actually hit: most damaged files are refused)
  EXPECT_GT(refused, 1000);
}

TEST(DamagedInput, RobotTomlParserNeverCrashes) {
  // GIVEN thousands of randomly damaged robot.toml files
  // WHEN each is parsed THEN each gives a robot or a located error
  expect_survives_damage(format_robot_toml(some_robot()),
                         [](const std::string& text) { return parse_robot_toml(text, "damaged"); });
}

TEST(DamagedInput, CalibrationTomlParserNeverCrashes) {
  // GIVEN thousands of randomly damaged calibration.toml files
  // WHEN each is parsed THEN each gives a calibration or a located error
  expect_survives_damage(format_calibration_toml(some_calibration()),
                         [](const std::string& text) { return parse_calibration_toml(text, "damaged"); });
}

TEST(DamagedInput, TruthTomlParserNeverCrashes) {
  // GIVEN thousands of randomly damaged truth.toml files
  Truth truth;
  truth.winches.resize(kCableCount);
  truth.effects["force_bias"] = {1.2};
  // WHEN each is parsed THEN each gives a truth or a located error
  expect_survives_damage(format_truth_toml(truth),
                         [](const std::string& text) { return parse_truth_toml(text, "damaged"); });
}

TEST(DamagedInput, SamplesCsvParserNeverCrashes) {
  // GIVEN thousands of randomly damaged samples.csv files
  // WHEN each is parsed THEN each gives samples or a located error
  expect_survives_damage(format_samples_csv(some_samples()), [](const std::string& text) {
    return parse_samples_csv(text, "damaged", kCableCount);
  });
}

TEST(DamagedInput, TableHeaderNotStartingWithAKeyIsASyntaxError) {
  // GIVEN table headers that break a precondition of toml++ 3.3.0's parse_key()
  // (found by fuzz_robot_toml: with assertions on, toml++ aborts; the shipped
  // library reports a parse error; upstream marzer/tomlplusplus#301)
  for (const std::string& header : std::vector<std::string>{"[[[1]]]", "[[[a]]]", "[[[]]", "[[=", "[\x01]"}) {
    // WHEN a robot.toml holding one is parsed
    const auto robot = parse_robot_toml(format_robot_toml(some_robot()) + header + "\n", "damaged");
    // THEN it is refused as a TOML syntax error on that line
    ASSERT_FALSE(robot.has_value()) << header;
    EXPECT_NE(robot.error().reason.find("TOML syntax"), std::string::npos) << robot.error().reason;
    EXPECT_GT(robot.error().line, 0) << header;
  }
}

}  // namespace
}  // namespace cdpr::formats
