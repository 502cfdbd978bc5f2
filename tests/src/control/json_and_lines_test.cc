#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "src/control/json_writer.h"
#include "src/control/line_assembler.h"

namespace cdpr::control {
namespace {

TEST(JsonWriter, EscapesQuotesControlBytesAndInvalidUtf8) {
  // GIVEN text with quotes, backslashes, newlines, a control byte, valid and invalid UTF-8
  const std::string text = std::string("a\"b\\c\nd\x01") + "\xc3\xa9" + "\xff" + "\xe2\x82";
  // WHEN written as a JSON string
  const std::string json = json_string(text);
  // THEN every special is escaped, valid UTF-8 kept, invalid bytes replaced by U+FFFD
  EXPECT_EQ(json, "\"a\\\"b\\\\c\\nd\\u0001\xc3\xa9\xef\xbf\xbd\xef\xbf\xbd\xef\xbf\xbd\"");
  EXPECT_EQ(json.find('\n'), std::string::npos);
}

TEST(JsonWriter, WritesNestedObjectsWithCommasAndNullForNonFinite) {
  // GIVEN a nested structure
  JsonWriter json;
  json.begin_object().key("ok").value(true).key("n").value(3).key("x").value(0.5);
  json.key("bad").value(std::numeric_limits<double>::infinity());
  json.key("list").begin_array().value("a").begin_object().key("k").value(false).end_object().end_array();
  json.end_object();
  // WHEN rendered THEN it is the expected one-line JSON
  EXPECT_EQ(json.text(), R"({"ok":true,"n":3,"x":0.5,"bad":null,"list":["a",{"k":false}]})");
}

struct Collected {
  std::vector<std::string> lines;
  int overlong = 0;
  void feed(LineAssembler& assembler, std::string_view bytes) {
    assembler.feed(bytes, [this](std::string_view line) { lines.emplace_back(line); }, [this] { ++overlong; });
  }
};

TEST(LineAssembler, JoinsLinesSplitAcrossReads) {
  // GIVEN two requests arriving in three pieces
  LineAssembler assembler(16);
  Collected out;
  // WHEN fed
  out.feed(assembler, "sta");
  out.feed(assembler, "tus\nrollb");
  out.feed(assembler, "ack 3\n");
  // THEN two whole lines come out and nothing is left over
  EXPECT_EQ(out.lines, (std::vector<std::string>{"status", "rollback 3"}));
  EXPECT_EQ(assembler.buffered(), 0u);
}

TEST(LineAssembler, AnOverlongLineIsReportedOnceAndSkippedToItsNewline) {
  // GIVEN a limit of 8 bytes
  LineAssembler assembler(8);
  Collected out;
  // WHEN a 30-byte line arrives in pieces, then a short one
  out.feed(assembler, std::string(10, 'a'));
  out.feed(assembler, std::string(20, 'b'));
  EXPECT_LE(assembler.buffered(), 8u);
  out.feed(assembler, "ccc\nshow\n");
  // THEN one overlong report, and the next line is intact
  EXPECT_EQ(out.overlong, 1);
  EXPECT_EQ(out.lines, (std::vector<std::string>{"show"}));
}

}  // namespace
}  // namespace cdpr::control
