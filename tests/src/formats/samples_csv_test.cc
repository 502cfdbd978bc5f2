#include "src/formats/samples_csv.h"

#include <cmath>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "format_test_support.h"

namespace cdpr::formats {
namespace {

// The samples.csv example of docs/FORMATS.md plus a second row.
const std::string kSamplesExample =
    "# lines starting with '#' are comments\n"
    "sample,x,y,z,qw,qx,qy,qz,enc0,enc1,enc2,enc3,force\n"
    "0,112.31,104.92,12.07,0.9998,0.0031,-0.0152,0.0004,171.233,182.904,166.118,190.451,702.4\n"
    "1,80.5,90.25,10.5,1,0,0,0,150.5,160.25,170.125,180.0625,650\n";

FormatError samples_parse_error(const std::string& text) {
  const auto samples = parse_samples_csv(text, "samples.csv", kCableCount);
  EXPECT_FALSE(samples.has_value());
  return samples ? FormatError{} : samples.error();
}

using test::BadEdit;

std::string samples_example_with(const std::string& from, const std::string& to) { return test::replaced(kSamplesExample, from, to); }

TEST(SamplesCsv, ExampleOfFormatsMdParses) {
  // GIVEN the documented example
  // WHEN it is parsed
  const auto samples = parse_samples_csv(kSamplesExample, "samples.csv", kCableCount);
  // THEN each row becomes a sample with its values in place
  ASSERT_TRUE(samples.has_value()) << samples.error().message();
  ASSERT_EQ(samples->size(), 2u);
  const Sample& s = (*samples)[0];
  EXPECT_EQ(s.id, 0);
  EXPECT_EQ(s.position_world, Eigen::Vector3d(112.31, 104.92, 12.07));
  EXPECT_EQ(s.encoder_m[0], 171.233);
  EXPECT_EQ(s.encoder_m[3], 190.451);
  EXPECT_EQ(s.force_n, 702.4);
  // (the quaternion is normalised: its norm is 0.99992, inside the tolerance)
  EXPECT_NEAR(s.world_R_platform.norm(), 1.0, 1e-15);
  const double norm = std::sqrt(0.9998 * 0.9998 + 0.0031 * 0.0031 + 0.0152 * 0.0152 + 0.0004 * 0.0004);
  EXPECT_NEAR(s.world_R_platform.y(), -0.0152 / norm, 1e-15);
  EXPECT_EQ((*samples)[1].id, 1);
  EXPECT_EQ((*samples)[1].world_R_platform.w(), 1.0);
}

TEST(SamplesCsv, ColumnsAreMatchedByNameWithSpacesAndCrlf) {
  // GIVEN shuffled columns, blanks around fields, CRLF line endings and blank lines
  const std::string text =
      "\r\n# exported by a spreadsheet\r\n"
      " force , enc3, enc2 ,enc1,enc0,qz,qy,qx,qw,z,y,x,sample \r\n"
      "\r\n"
      "702.4, 190.451,166.118,182.904,171.233,0,0,0,1,12.07,104.92,112.31, 7\r\n";
  // WHEN it is parsed
  const auto samples = parse_samples_csv(text, "samples.csv", kCableCount);
  // THEN every value lands in its named field
  ASSERT_TRUE(samples.has_value()) << samples.error().message();
  ASSERT_EQ(samples->size(), 1u);
  const Sample& s = (*samples)[0];
  EXPECT_EQ(s.id, 7);
  EXPECT_EQ(s.position_world, Eigen::Vector3d(112.31, 104.92, 12.07));
  EXPECT_EQ(s.world_R_platform.coeffs(), Eigen::Quaterniond::Identity().coeffs());
  EXPECT_EQ(s.encoder_m[0], 171.233);
  EXPECT_EQ(s.encoder_m[1], 182.904);
  EXPECT_EQ(s.encoder_m[2], 166.118);
  EXPECT_EQ(s.encoder_m[3], 190.451);
  EXPECT_EQ(s.force_n, 702.4);
}

class SamplesCsvBadInput : public testing::TestWithParam<BadEdit> {};

TEST_P(SamplesCsvBadInput, IsRefusedWithLineColumnAndReason) {
  // GIVEN the example with one thing spoilt
  const BadEdit& bad = GetParam();
  const std::string text = samples_example_with(bad.from, bad.to);
  // WHEN it is parsed
  const FormatError error = samples_parse_error(text);
  // THEN the error names the file line, the column and why
  EXPECT_EQ(error.file, "samples.csv");
  test::expect_refusal(error, bad, text);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, SamplesCsvBadInput,
    testing::Values(
        BadEdit{"nan", "171.233", "nan", "enc0", "not a finite number: 'nan'", 3},
        BadEdit{"inf", "702.4", "-inf", "force", "not a finite number", 3},
        BadEdit{"empty value", ",12.07,", ",,", "z", "missing value", 3},
        BadEdit{"non-numeric", "104.92", "1o4.92", "y", "not a number: '1o4.92'", 3},
        BadEdit{"decimal comma", "104.92", "104,92", "", "row has 14 values but the header has 13 columns", 3},
        BadEdit{"text value", "150.5", "abc", "enc0", "not a number: 'abc'", 4},
        BadEdit{"trailing junk", "150.5", "150.5m", "enc0", "not a number: '150.5m'", 4},
        BadEdit{"short row", ",650\n", "\n", "force", "row has 12 values but the header has 13 columns", 4},
        BadEdit{"long row", ",650\n", ",650,1\n", "", "row has 14 values", 4},
        BadEdit{"fractional id", "\n1,", "\n1.5,", "sample", "sample id must be an integer, got '1.5'", 4},
        BadEdit{"duplicate id", "\n1,", "\n0,", "sample", "duplicate sample id 0 (first on line 3)", 4},
        BadEdit{"bad quaternion", "1,0,0,0,150.5", "0.93,0,0,0,150.5", "qw..qz", "quaternion norm 0.93 is not 1", 4},
        BadEdit{"unknown column", "enc3", "enc4", "enc4", "unknown column 12: the robot has 4 cables, enc0..enc3", 2},
        BadEdit{"misspelt column", "force", "forse", "forse", "unknown column 13 (did you mean 'force'?)", 2},
        BadEdit{"foreign column", "force", "temperature", "temperature", "expected the columns sample,x,y,z", 2},
        BadEdit{"duplicate column", ",y,", ",x,", "x", "duplicate column (columns 2 and 3)", 2},
        BadEdit{"missing column", ",enc2", "", "enc2", "missing column", 2},
        BadEdit{"empty column name", "qz,", "qz,,", "", "column 9 has no name", 2}),
    test::case_name);

TEST(SamplesCsv, QuaternionJustInsideToleranceIsNormalised) {
  // GIVEN a quaternion whose norm is 1.0009
  const std::string text = samples_example_with("1,0,0,0,150.5", "1.0009,0,0,0,150.5");
  // WHEN it is parsed
  const auto samples = parse_samples_csv(text, "samples.csv", kCableCount);
  // THEN it is accepted as a unit quaternion
  ASSERT_TRUE(samples.has_value()) << samples.error().message();
  EXPECT_EQ((*samples)[1].world_R_platform.w(), 1.0);
}

TEST(SamplesCsv, HeaderWithoutRowsIsRefused) {
  // GIVEN only comments and the header
  const std::string text = kSamplesExample.substr(0, kSamplesExample.find("\n0,") + 1);
  // WHEN it is parsed
  const FormatError error = samples_parse_error(text);
  // THEN it says there are no data rows, at the header's line
  EXPECT_EQ(error.reason, "no data rows");
  EXPECT_EQ(error.line, 2);
}

TEST(SamplesCsv, EmptyFileIsRefused) {
  // GIVEN only a comment
  // WHEN it is parsed
  const FormatError error = samples_parse_error("# nothing here\n");
  // THEN it asks for the header and spells it out
  EXPECT_NE(error.reason.find("no header line"), std::string::npos) << error.reason;
  EXPECT_NE(error.reason.find("sample,x,y,z,qw,qx,qy,qz,enc0,enc1,enc2,enc3,force"), std::string::npos);
}

TEST(SamplesCsv, OtherCableCountsAreRefused) {
  // GIVEN a request for three cables
  // WHEN the example is parsed
  const auto samples = parse_samples_csv(kSamplesExample, "samples.csv", 3);
  // THEN it is refused naming the counts
  ASSERT_FALSE(samples.has_value());
  EXPECT_NE(samples.error().reason.find("3 cables"), std::string::npos) << samples.error().reason;
}

TEST(SamplesCsv, FormatThenParseGivesTheSameSamples) {
  // GIVEN samples with values that need all 17 digits and rotated orientations
  std::vector<Sample> samples;
  for (int k = 0; k < 5; ++k) {
    Sample s;
    s.id = 10 * k - 3;
    s.position_world = Eigen::Vector3d(100.0 / 3.0 + k, -0.1 * k, 1e-300 + k);
    s.world_R_platform = Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * k + 0.05, Eigen::Vector3d(1, 2, 3).normalized()));
    for (int i = 0; i < kCableCount; ++i) s.encoder_m[i] = 150.0 + std::sqrt(2.0 + i + k);
    s.force_n = 700.0 / 7.1 + k;
    samples.push_back(s);
  }
  // WHEN they are formatted and parsed again
  const std::string text = format_samples_csv(samples);
  const auto again = parse_samples_csv(text, "written.csv", kCableCount);
  // THEN every value is bit-identical
  ASSERT_TRUE(again.has_value()) << again.error().message() << "\n" << text;
  ASSERT_EQ(again->size(), samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) {
    EXPECT_EQ((*again)[k].id, samples[k].id);
    EXPECT_EQ((*again)[k].position_world, samples[k].position_world);
    EXPECT_EQ((*again)[k].world_R_platform.coeffs(), samples[k].world_R_platform.coeffs());
    EXPECT_EQ((*again)[k].encoder_m, samples[k].encoder_m);
    EXPECT_EQ((*again)[k].force_n, samples[k].force_n);
  }
}

const std::string kWithSigmas =
    "sample,x,y,z,qw,qx,qy,qz,enc0,enc1,enc2,enc3,force,sigma_enc0,sigma_enc1,sigma_enc2,sigma_enc3,sigma_force,"
    "sigma_pos,sigma_rot\n"
    "0,112.31,104.92,12.07,1,0,0,0,171.233,182.904,166.118,190.451,702.4,0.001,0.002,0.003,0.004,0.5,0.0006,0.0007\n"
    "1,80.5,90.25,10.5,1,0,0,0,150.5,160.25,170.125,180.0625,650,,,,,,,\n";

TEST(SamplesCsv, SigmaColumnsAreReadPerRow) {
  // GIVEN a file with the optional sigma columns, the second row leaving them empty
  // WHEN it is parsed
  const auto samples = parse_samples_csv(kWithSigmas, "samples.csv", kCableCount);
  // THEN the first row has its own sigmas, the second none
  ASSERT_TRUE(samples.has_value()) << samples.error().message();
  ASSERT_TRUE((*samples)[0].has_own_sigma());
  EXPECT_EQ((*samples)[0].sigma.encoder_m, (std::array<double, kCableCount>{0.001, 0.002, 0.003, 0.004}));
  EXPECT_EQ((*samples)[0].sigma.force_n, 0.5);
  EXPECT_EQ((*samples)[0].sigma.position_m, 0.0006);
  EXPECT_EQ((*samples)[0].sigma.orientation_rad, 0.0007);
  EXPECT_FALSE((*samples)[1].has_own_sigma());
}

TEST(SamplesCsv, FileWithoutSigmaColumnsHasNoRowSigmas) {
  const auto samples = parse_samples_csv(kSamplesExample, "samples.csv", kCableCount);
  ASSERT_TRUE(samples.has_value());
  for (const Sample& s : *samples) EXPECT_FALSE(s.has_own_sigma());
}

TEST(SamplesCsv, SigmaColumnsComeAllTogetherAndPositive) {
  // GIVEN one sigma column missing THEN the header is refused naming it
  const FormatError missing = samples_parse_error(test::replaced(kWithSigmas, ",sigma_rot", ""));
  EXPECT_EQ(missing.field, "sigma_rot");
  EXPECT_NE(missing.reason.find("all together"), std::string::npos) << missing.reason;
  // GIVEN a row with some sigmas empty THEN the row is refused
  const FormatError partial = samples_parse_error(test::replaced(kWithSigmas, ",0.0007\n", ",\n"));
  EXPECT_EQ(partial.field, "sigma_rot");
  EXPECT_EQ(partial.line, 2);
  // GIVEN a zero sigma THEN refused
  const FormatError zero = samples_parse_error(test::replaced(kWithSigmas, ",0.5,", ",0,"));
  EXPECT_EQ(zero.field, "sigma_force");
  EXPECT_NE(zero.reason.find("> 0"), std::string::npos) << zero.reason;
}

TEST(SamplesCsv, FormatThenParseKeepsRowSigmas) {
  // GIVEN two samples, one with its own sigmas and one without
  std::vector<Sample> samples(2);
  samples[0].id = 0;
  samples[1].id = 1;
  samples[0].sigma = SampleSigmas{{1.0 / 3.0, 2e-4, 3e-4, 4e-4}, 0.25, 1.0 / 7.0, 2e-5};
  // WHEN formatted and parsed again
  const std::string text = format_samples_csv(samples);
  const auto again = parse_samples_csv(text, "written.csv", kCableCount);
  // THEN the sigmas come back bit-identical, and the row without stays without
  ASSERT_TRUE(again.has_value()) << again.error().message() << "\n" << text;
  ASSERT_TRUE((*again)[0].has_own_sigma());
  EXPECT_EQ((*again)[0].sigma.encoder_m, samples[0].sigma.encoder_m);
  EXPECT_EQ((*again)[0].sigma.force_n, samples[0].sigma.force_n);
  EXPECT_EQ((*again)[0].sigma.position_m, samples[0].sigma.position_m);
  EXPECT_EQ((*again)[0].sigma.orientation_rad, samples[0].sigma.orientation_rad);
  EXPECT_FALSE((*again)[1].has_own_sigma());
}

TEST(SamplesCsv, SamplesWithoutSigmasAreWrittenAsBefore) {
  // GIVEN samples without their own sigmas WHEN formatted
  std::vector<Sample> samples(1);
  const std::string text = format_samples_csv(samples);
  // THEN the header has no sigma column
  EXPECT_EQ(text.find("sigma"), std::string::npos) << text;
  EXPECT_NE(text.find("\nsample,x,y,z,qw,qx,qy,qz,enc0,enc1,enc2,enc3,force\n"), std::string::npos) << text;
}

}  // namespace
}  // namespace cdpr::formats
