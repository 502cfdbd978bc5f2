// The pose line parser: every kind of malformed line is refused with its
// reason; good lines round-trip through format_pose_line.

#include "drivers/pose/pose_line.h"

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

namespace cdpr::drivers::pose {
namespace {

PoseLineResult parse(const std::string& line) {
  hal::PoseSample sample;
  return parse_pose_line(line, sample);
}

TEST(PoseLine, ParsesAGoodLine) {
  // GIVEN a well-formed line with CRLF ending and extra blanks
  hal::PoseSample sample;
  // WHEN parsed
  const PoseLineResult result = parse_pose_line("POSE 123456  1.5 -2.25\t3e-1 1 0 0 0 1\r", sample);
  // THEN every field lands in its place
  ASSERT_EQ(result, PoseLineResult::kSample);
  EXPECT_EQ(sample.source_time_us, 123456);
  EXPECT_DOUBLE_EQ(sample.platform_world.x, 1.5);
  EXPECT_DOUBLE_EQ(sample.platform_world.y, -2.25);
  EXPECT_DOUBLE_EQ(sample.platform_world.z, 0.3);
  EXPECT_DOUBLE_EQ(sample.world_R_platform.w, 1.0);
  EXPECT_TRUE(sample.valid);
  EXPECT_EQ(sample.received_us, 0);
}

TEST(PoseLine, RefusesEachKindOfDamage) {
  EXPECT_EQ(parse(""), PoseLineResult::kComment);
  EXPECT_EQ(parse("  # a comment"), PoseLineResult::kComment);
  EXPECT_EQ(parse("POS 1 0 0 0 1 0 0 0 1"), PoseLineResult::kNotPose);
  EXPECT_EQ(parse("POSE 1 0 0 0 1 0 0 0"), PoseLineResult::kFieldCount);
  EXPECT_EQ(parse("POSE 1 0 0 0 1 0 0 0 1 7"), PoseLineResult::kFieldCount);
  EXPECT_EQ(parse("POSE 1.5 0 0 0 1 0 0 0 1"), PoseLineResult::kBadNumber);
  EXPECT_EQ(parse("POSE 1 0 0x1 0 1 0 0 0 1"), PoseLineResult::kBadNumber);
  EXPECT_EQ(parse("POSE 1 0 0 0 1 0 0 0 yes"), PoseLineResult::kBadNumber);
  EXPECT_EQ(parse("POSE 1 nan 0 0 1 0 0 0 1"), PoseLineResult::kNonFinite);
  EXPECT_EQ(parse("POSE 1 0 inf 0 1 0 0 0 1"), PoseLineResult::kNonFinite);
  EXPECT_EQ(parse("POSE 1 0 0 0 1 1 0 0 1"), PoseLineResult::kBadQuaternion);
  EXPECT_EQ(parse("POSE 1 0 0 0 0 0 0 0 1"), PoseLineResult::kBadQuaternion);
  EXPECT_EQ(parse("POSE 1 0 0 0 1 0 0 0 2"), PoseLineResult::kBadValid);
  EXPECT_EQ(parse("POSE 1 0 0 0 1 0 0 0 1" + std::string(300, ' ')), PoseLineResult::kTooLong);
}

TEST(PoseLine, RenormalisesANearlyUnitQuaternion) {
  hal::PoseSample sample;
  ASSERT_EQ(parse_pose_line("POSE 0 0 0 0 1.0005 0 0 0 0", sample), PoseLineResult::kSample);
  EXPECT_DOUBLE_EQ(sample.world_R_platform.w, 1.0);
  EXPECT_FALSE(sample.valid);
}

TEST(PoseLine, FormatRoundTrips) {
  // GIVEN an awkward sample
  hal::PoseSample in;
  in.source_time_us = -42;
  in.platform_world = {0.1, -1e-9, 12345.678901234};
  const double s = std::sqrt(0.5);
  in.world_R_platform = {s, 0.0, -s, 0.0};
  in.valid = true;
  // WHEN formatted and parsed back THEN the values are identical
  std::string line = format_pose_line(in);
  ASSERT_EQ(line.back(), '\n');
  line.pop_back();
  hal::PoseSample out;
  ASSERT_EQ(parse_pose_line(line, out), PoseLineResult::kSample) << line;
  EXPECT_EQ(out.source_time_us, in.source_time_us);
  EXPECT_DOUBLE_EQ(out.platform_world.y, in.platform_world.y);
  EXPECT_DOUBLE_EQ(out.platform_world.z, in.platform_world.z);
  EXPECT_NEAR(out.world_R_platform.z, in.world_R_platform.z, 1e-15);
  EXPECT_TRUE(out.valid);
}

TEST(PoseLine, RandomBytesNeverCrash) {
  // GIVEN many random byte strings (and mutations of a good line)
  std::mt19937 random(12345);
  std::uniform_int_distribution<int> byte(0, 255);
  const std::string good = "POSE 1 0.5 0.5 0.5 1 0 0 0 1";
  int accepted = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::string line = good;
    const int edits = 1 + trial % 4;
    for (int e = 0; e < edits; ++e) line[random() % line.size()] = static_cast<char>(byte(random));
    if (trial % 5 == 0) line.assign(random() % 300, static_cast<char>(byte(random)));
    // WHEN parsed THEN it returns (ASan/UBSan builds check memory) and what it accepts is finite
    hal::PoseSample sample;
    if (parse_pose_line(line, sample) == PoseLineResult::kSample) {
      ++accepted;
      EXPECT_TRUE(std::isfinite(sample.platform_world.x + sample.platform_world.y + sample.platform_world.z));
    }
  }
  EXPECT_LT(accepted, 20000);
}

}  // namespace
}  // namespace cdpr::drivers::pose
