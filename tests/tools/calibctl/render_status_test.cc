// calibctl status's text (tools/calibctl/render.h): a long note is wrapped
// and every label keeps a line of its own; the run's time is named as the
// daemon's clock; the hint to commit a refit goes once that refit is committed.
#include "calibctl/render.h"

#include <algorithm>
#include <sstream>

#include <gtest/gtest.h>

#include "calibctl/json_value.h"

namespace cdpr::calibctl {
namespace {

std::string status_with(const std::string& members) {
  const auto json = JsonValue::parse(R"({"ok":true,"state":"failed","running":false,"waypoint":3,"waypoints":10,)"
                                     R"("samples":2,"skipped":0,"progress":0.3,"elapsed_s":41.2,)"
                                     R"("strategy":"spread","stop_reason":"","sigma":null,"time_left_s":null,)" +
                                     members + "}");
  EXPECT_TRUE(json.has_value()) << members;
  return json ? render_status(*json) : std::string();
}

const std::string kRun =
    R"("run":{"entry":"/var/lib/cdpr-calib/history/run-000007","outcome":"failed","samples":2,)"
    R"("diagnosis":"the catenary alone does not fit the data","named_terms":["load_cell_bias"]})";

TEST(CalibctlStatus, ALongNoteIsWrappedAndReasonAndRunKeepLinesOfTheirOwn) {
  // GIVEN a note of about 1100 characters
  std::string note;
  for (int k = 0; k < 110; ++k) note += "word" + std::to_string(k % 10) + "xx ";
  const std::string text = status_with(R"("reason":"store: write failed","note":")" + note +
                                       R"(","detail":"","device_faults":"","committed_seq":0,"interrupted":"",)"
                                       R"("store_problems":[],"pending_commit":false,)" +
                                       kRun + R"(,"refit":null)");
  // THEN no line is longer than 100 characters, and reason and run start lines of their own
  std::istringstream lines(text);
  std::string all_words;
  for (std::string line; std::getline(lines, line);) {
    EXPECT_LE(line.size(), 100u) << line;
    all_words += line + " ";
  }
  EXPECT_NE(text.find("\n  reason: store: write failed\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\n  run: failed, 2 samples, data in /var/lib/cdpr-calib/history/run-000007\n"),
            std::string::npos)
      << text;
  // AND the whole note is there
  EXPECT_NE(all_words.find("word9xx"), std::string::npos);
  EXPECT_EQ(std::count(text.begin(), text.end(), 'x'), 220) << text;
}

TEST(CalibctlStatus, TheRunsTimeIsTheDaemonsClockNotTheRobots) {
  const std::string text = status_with(R"("reason":"","note":"","detail":"","device_faults":"","committed_seq":0,)"
                                       R"("interrupted":"","store_problems":[],"pending_commit":false,"run":null,)"
                                       R"("refit":null)");
  EXPECT_NE(text.find("spread: elapsed 41.2 s (daemon clock)"), std::string::npos) << text;
  EXPECT_EQ(text.find("robot time"), std::string::npos) << text;
}

TEST(CalibctlStatus, TheRefitHintGoesOnceThatRefitIsCommitted) {
  const std::string before = R"("reason":"","note":"","detail":"","device_faults":"","committed_seq":0,)"
                             R"("interrupted":"","store_problems":[],"pending_commit":false,)" +
                             kRun + ",";
  // GIVEN a run whose model check named a term WHEN no refit was made THEN status suggests the command
  EXPECT_NE(status_with(before + R"("refit":null)").find("calibctl commit --with-term load_cell_bias run-000007"),
            std::string::npos);
  // WHEN that refit was committed THEN the hint is gone
  const std::string committed =
      status_with(before + R"("refit":{"run":"run-000007","terms":"load_cell_bias","state":"committed",)"
                           R"("message":"committed calibration 5","committed_seq":5,"entry":""})");
  EXPECT_EQ(committed.find("calibctl commit --with-term"), std::string::npos) << committed;
}

}  // namespace
}  // namespace cdpr::calibctl
