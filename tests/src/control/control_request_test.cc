#include "src/control/control_request.h"

#include <random>

#include <gtest/gtest.h>

namespace cdpr::control {
namespace {

TEST(ControlRequest, EveryCommandParses) {
  // GIVEN each request of the language, WHEN parsed, THEN its kind (and seq) come out
  EXPECT_EQ(parse_request("start")->kind, RequestKind::kStart);
  EXPECT_EQ(parse_request("abort\n")->kind, RequestKind::kAbort);
  EXPECT_EQ(parse_request("status\r\n")->kind, RequestKind::kStatus);
  EXPECT_EQ(parse_request("  show \t")->kind, RequestKind::kShow);
  EXPECT_EQ(parse_request("history")->kind, RequestKind::kHistory);
  EXPECT_EQ(parse_request("reset-faults")->kind, RequestKind::kResetFaults);
  const auto rollback = parse_request("rollback   42\n");
  ASSERT_TRUE(rollback);
  EXPECT_EQ(rollback->kind, RequestKind::kRollback);
  EXPECT_EQ(rollback->seq, 42);
}

TEST(ControlRequest, RefitNamesItsTermsAndOptionallyItsRun) {
  // GIVEN refit requests with and without a run, in both spellings
  const auto newest = parse_request("refit load_cell_bias");
  const auto numbered = parse_request("refit elasticity,load_cell_bias 7\n");
  const auto named = parse_request("refit  load_cell_bias\trun-000012");
  // THEN the terms are passed on as given and the run as its number (0: the newest)
  ASSERT_TRUE(newest && numbered && named);
  EXPECT_EQ(newest->kind, RequestKind::kRefit);
  EXPECT_EQ(newest->terms, "load_cell_bias");
  EXPECT_EQ(newest->run, 0);
  EXPECT_EQ(numbered->terms, "elasticity,load_cell_bias");
  EXPECT_EQ(numbered->run, 7);
  EXPECT_EQ(named->run, 12);
  // AND a missing term, a bad run or too many words are refused with the reason
  EXPECT_EQ(parse_request("refit").error(), "refit takes one or two arguments: <terms> [<run>]");
  EXPECT_EQ(parse_request("refit a 3 4").error(), "refit takes one or two arguments: <terms> [<run>]");
  EXPECT_EQ(parse_request("refit load_cell_bias 0").error(), "run '0' is not a run number (7 or run-000007)");
  EXPECT_EQ(parse_request("refit load_cell_bias run-x").error(), "run 'run-x' is not a run number (7 or run-000007)");
}

TEST(ControlRequest, MistakesAreRefusedWithAReason) {
  // GIVEN malformed requests WHEN parsed THEN each error says what is wrong
  EXPECT_EQ(parse_request("strat").error(),
            "unknown command 'strat' (expected start [waypoints <path> [<run>]], abort, status, show, history, "
            "rollback <seq>, commit, reset-faults or refit <terms> [<run>])");
  EXPECT_EQ(parse_request("").error().substr(0, 13), "empty request");
  EXPECT_EQ(parse_request("START").error().substr(0, 15), "unknown command");
  EXPECT_EQ(parse_request("start now").error(), "start takes no argument or: waypoints <path> [<run>]");
  EXPECT_EQ(parse_request("rollback").error(), "rollback takes one argument: <seq>");
  EXPECT_EQ(parse_request("rollback 0").error(), "sequence number '0' is not an integer in 1..999999999");
  EXPECT_FALSE(parse_request("rollback -3"));
  EXPECT_FALSE(parse_request("rollback 1234567890"));
  EXPECT_FALSE(parse_request("rollback 1e3"));
  EXPECT_FALSE(parse_request("rollback 3 4"));
  EXPECT_EQ(parse_request(std::string("sta\0rt", 6)).error(), "request contains a non-ASCII or control byte");
  EXPECT_EQ(parse_request("status\n\n").error(), "request contains a non-ASCII or control byte");
  EXPECT_EQ(parse_request(std::string(300, 's')).error(), "request longer than 256 bytes");
}

TEST(ControlRequest, EchoedWordsAreSanitisedAndShortened) {
  // GIVEN a long unknown word
  const std::string long_word(100, 'x');
  // WHEN parsed THEN the echo is cut to 32 characters
  const std::string error = parse_request(long_word).error();
  EXPECT_NE(error.find("'" + std::string(32, 'x') + "...'"), std::string::npos) << error;
}

TEST(ControlRequest, RandomBytesNeverCrashAndOnlyTheLanguageIsAccepted) {
  // GIVEN many random lines, biased towards the language's words
  std::mt19937 random(7);
  const std::string pieces[] = {"start", "abort", "status", "show", "history", "rollback", " ", "\t", "1", "0",
                                "99",    "\r",    "\n",     "\x80", "-",       "x",        "\0"};
  int accepted = 0;
  for (int trial = 0; trial < 100000; ++trial) {
    std::string line;
    const int count = static_cast<int>(random() % 5);
    for (int k = 0; k < count; ++k) {
      if (random() % 4 == 0) {
        line += static_cast<char>(random() % 256);
      } else {
        line += pieces[random() % std::size(pieces)];
      }
    }
    // WHEN parsed
    const auto request = parse_request(line);
    // THEN an accepted line re-spelt canonically parses to the same request
    if (request) {
      ++accepted;
      std::string canonical = to_string(request->kind);
      if (request->kind == RequestKind::kRollback) canonical += " " + std::to_string(request->seq);
      const auto again = parse_request(canonical);
      ASSERT_TRUE(again) << canonical;
      EXPECT_EQ(again->kind, request->kind);
      EXPECT_EQ(again->seq, request->seq);
    } else {
      EXPECT_FALSE(request.error().empty());
    }
  }
  EXPECT_GT(accepted, 100);
}

}  // namespace
}  // namespace cdpr::control
