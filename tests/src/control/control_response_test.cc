#include "src/control/control_response.h"

#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace cdpr::control {
namespace {

TEST(ControlResponse, TextIsEscapedOnOneLineAndInvalidUtf8Replaced) {
  // GIVEN a reason with quotes, backslashes, a newline, a control byte, valid and invalid UTF-8
  const std::string reason = std::string("a\"b\\c\nd\x01") + "\xc3\xa9" + "\xff" + "x";
  // WHEN sent as an error response
  const std::string response = format_error_response(reason);
  // THEN every special is escaped, valid UTF-8 kept, the invalid byte replaced by U+FFFD, one line
  EXPECT_EQ(response, "{\"ok\":false,\"error\":\"a\\\"b\\\\c\\nd\\u0001\xc3\xa9\xef\xbf\xbdx\"}\n");
}

TEST(ControlResponse, NumbersAreTheShortestTextThatReadsBackAndNonFiniteIsNull) {
  // GIVEN a run 41 s in, at progress 1e-4
  calibration::CalibrationStatus status;
  status.started_us = 1'000'000;
  status.progress = 1e-4;
  // WHEN its status is written
  const std::string response = format_status_response(status, 42'000'000);
  // THEN whole numbers have no ".0" and small ones take the shorter exponent form
  EXPECT_NE(response.find("\"progress\":1e-04,\"elapsed_s\":41,"), std::string::npos) << response;
  // AND a progress that is not finite is null
  status.progress = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(format_status_response(status, 42'000'000).find("\"progress\":null,"), std::string::npos);
}

TEST(ControlResponse, StatusListsEveryNodeWithItsStates) {
  // GIVEN a drive in quick stop active after a heartbeat loss, and an encoder never heard
  calibration::CalibrationStatus status;
  hal::NodeStatus drive;
  drive.role = "drive";
  drive.node_id = 1;
  drive.nmt = "operational";
  drive.configured = true;
  drive.power_state = "quick stop active";
  drive.emcy_code = 0x8130;
  drive.emcy_register = 0x11;
  drive.emcy_text = "life guard or heartbeat error";
  drive.pdo_age_us = 12'500;
  drive.heartbeat_age_us = 40'000;
  hal::NodeStatus encoder;
  encoder.role = "encoder";
  encoder.node_id = 11;
  status.nodes = {{0, drive}, {0, encoder}};
  // WHEN its status is written
  const std::string response = format_status_response(status, 42'000'000);
  // THEN each node has its states, 0x603F, last EMCY and ages (null when never heard)
  EXPECT_NE(response.find("\"nodes\":[{\"winch\":0,\"role\":\"drive\",\"node_id\":1,\"nmt\":\"operational\","
                          "\"configured\":true,\"cia402\":\"quick stop active\",\"error_code\":\"\","
                          "\"last_emcy\":\"0x8130 (life guard or heartbeat error)\",\"emcy_register\":17,"
                          "\"pdo_age_ms\":12.5,\"heartbeat_age_ms\":40},{\"winch\":0,\"role\":\"encoder\","
                          "\"node_id\":11,\"nmt\":\"unknown\",\"configured\":false,\"cia402\":\"\","
                          "\"error_code\":\"\",\"last_emcy\":\"\",\"emcy_register\":0,\"pdo_age_ms\":null,"
                          "\"heartbeat_age_ms\":null}],\"operation\":null}\n"),
            std::string::npos)
      << response;
}

TEST(ControlResponse, HistoryKeepsItsFieldOrder) {
  // GIVEN one valid and one unreadable stored version WHEN listed
  std::vector<store::HistoryEntry> history(2);
  history[0] = {2, "/s/history/2.toml", true, true, "2026-11-22T10:15:00Z", "large", 35, ""};
  history[1] = {1, "/s/history/1.toml", false, false, "", "", 0, "format 2 not supported"};
  // THEN each entry's members come in the documented order
  EXPECT_EQ(format_history_response(history),
            "{\"ok\":true,\"history\":[{\"seq\":2,\"current\":true,\"valid\":true,\"created\":\"2026-11-22T10:15:00Z\","
            "\"robot\":\"large\",\"samples\":35,\"problem\":\"\"},{\"seq\":1,\"current\":false,\"valid\":false,"
            "\"created\":\"\",\"robot\":\"\",\"samples\":0,\"problem\":\"format 2 not supported\"}]}\n");
}

}  // namespace
}  // namespace cdpr::control
