#include "src/control/line_assembler.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace cdpr::control {
namespace {

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
