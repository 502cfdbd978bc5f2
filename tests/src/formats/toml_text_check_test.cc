// The check that keeps toml++ 3.3.0 away from its undefined behaviour on some
// non-ASCII text (src/formats/toml_text_check.h), alone and through the
// parsers: what toml++ would mishandle is refused with its line, non-ASCII
// text where TOML allows it still parses.

#include "src/formats/toml_text_check.h"

#include <string>

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/text_file.h"

namespace cdpr::formats {
namespace {

TEST(TomlTextCheck, RefusesNonAsciiOutsideStringsAndCommentsWithItsLine) {
  // GIVEN non-ASCII bytes where toml++ tests for whitespace: bare, after a
  // number (the fuzzer's find, U+0362), in a key, after a line-ending backslash
  // of a """ string (upstream #190, U+00A7)
  struct Case {
    std::string text;
    int line;
  };
  for (const Case& bad : {Case{"\xcc\xaa", 1}, Case{"a = 1\nb = [0.0, 50.\xcd\xa2]\n", 2},
                          Case{"# ok\n\n k\xc3\xbc = 1\n", 3}, Case{"s = \"\"\"\\\n\xc2\xa7\"\"\"\n", 2},
                          Case{"s = \"\"\"\\  \r\n\n   \xc2\xa7\"\"\"\n", 3},
                          // a quote inside a bare value opens no string for toml++ (fuzz_robot_toml, U+025F)
                          Case{"x = [0.0\"\"\"c\xc9\x9f\"\"\"]\n", 1},
                          Case{"d = 1979-05-27 07:32:00\"\xc9\x9f\"\n", 1},
                          Case{"a = [\n 1,\n # c\n 2\"\xc9\x9f\"]\n", 4}, Case{"t = {a = 1, b = 2'\xc9\x9f'}\n", 1},
                          // right after a backslash, or after blanks following it, in a string (U+FEF7, U+FE7F)
                          Case{"s = \"\"\"-\n = nchT\\\xef\xbb\xb7 }\"\"\"\n", 2}, Case{"s = \"a\\\xc9\x9f\"\n", 1},
                          Case{"s = \"a\\ \xef\xb9\xbf\"\n", 1}}) {
    // WHEN checked THEN refused at its line
    const auto error = find_unsafe_non_ascii(bad.text, "f.toml");
    ASSERT_TRUE(error.has_value()) << bad.text;
    EXPECT_EQ(error->line, bad.line) << bad.text;
    EXPECT_NE(error->reason.find("non-ASCII"), std::string::npos);
  }
}

TEST(TomlTextCheck, AcceptsNonAsciiInStringsAndComments) {
  // GIVEN non-ASCII text in every place TOML allows it, with the delimiters
  // that could make a scanner lose track (escaped quotes, """"" endings)
  for (const std::string good :
       {"name = \"Gro\xc3\x9f \\\"\xc3\xbc\\\" Roboter\" # K\xc3\xb6ln\n", "n = 'caf\xc3\xa9'\n",
        "s = \"\"\"\n\xc2\xa7 line \\\" two \xc2\xa7\"\"\"\"\"\nt = 1 # \xc2\xa7\n", "s = '''\xc2\xa7'''''\n",
        "s = \"\"\"x\\n\xc2\xa7\"\"\"\n",
        // strings where values and keys start: in arrays, inline tables, dotted keys, table headers
        "a.\"\xc9\x9f\" = 1\n", "x = [\"\xc9\x9f\", '\xc9\x9f', \"\"\"\xc9\x9f\"\"\"]\n",
        "t = {a = \"\xc9\x9f\", \"\xc9\x9f\" = 1}\n", "[a.\"\xc9\x9f\"]\nk = 1\n",
        "x = [\n 1, # \xc9\x9f\n \"\xc9\x9f\",\n]\n",
        // after an escaped backslash
        "s = \"a\\\\\xc9\x9f\"\n", "s = \"\"\"a\\\\\xc9\x9f\"\"\"\n"}) {
    // WHEN checked THEN nothing is refused
    EXPECT_FALSE(find_unsafe_non_ascii(good, "f.toml").has_value()) << good;
  }
}

TEST(TomlTextCheck, ParsersRefuseTheFuzzersInputsAndKeepNonAsciiNames) {
  // GIVEN the input that made fuzz_calibration_toml reach toml++'s unreachable code
  const auto crashing = read_text_file(std::string(CDPR_SOURCE_DIR) +
                                       "/tests/fuzz/corpus/calibration_toml/non_ascii_after_number_crash.toml");
  ASSERT_TRUE(crashing.has_value());
  // WHEN parsed THEN it is refused as non-ASCII text at its line
  const auto calibration = parse_calibration_toml(*crashing, "crash.toml");
  ASSERT_FALSE(calibration.has_value());
  EXPECT_NE(calibration.error().reason.find("non-ASCII"), std::string::npos) << calibration.error().message();
  EXPECT_GT(calibration.error().line, 0);
  // AND so are the later finds: a multi-line string opener inside a number,
  // non-ASCII text after a backslash in a string
  for (const char* later : {"robot_toml/quote_inside_number_crash.toml", "robot_toml/non_ascii_after_backslash_crash.toml",
                            "calibration_toml/non_ascii_after_backslash_crash.toml"}) {
    const auto input = read_text_file(std::string(CDPR_SOURCE_DIR) + "/tests/fuzz/corpus/" + later);
    ASSERT_TRUE(input.has_value()) << later;
    const auto refused = parse_robot_toml(*input, "crash.toml");
    ASSERT_FALSE(refused.has_value()) << later;
    EXPECT_NE(refused.error().reason.find("non-ASCII"), std::string::npos) << refused.error().message();
  }
  // AND a robot named with non-ASCII letters still round-trips
  Robot robot;
  robot.name = "Gro\xc3\x9f\xc3\xa9r Roboter";
  robot.platform_mass_kg = 34.0;
  robot.cable_linear_density_kgpm = 0.07;
  for (int i = 0; i < kCableCount; ++i) robot.winches.push_back({Eigen::Vector3d(i, 0, 50), Eigen::Vector3d::Zero()});
  const auto again = parse_robot_toml(format_robot_toml(robot), "robot.toml");
  ASSERT_TRUE(again.has_value()) << again.error().message();
  EXPECT_EQ(again->name, robot.name);
}

}  // namespace
}  // namespace cdpr::formats
