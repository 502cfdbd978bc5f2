// calibctl status's text (tools/calibctl/render.h) of the bus nodes: one
// line per node with its NMT and CiA 402 state, 0x603F, last EMCY, PDO age.
#include <gtest/gtest.h>

#include "calibctl/json_value.h"
#include "calibctl/render.h"

namespace cdpr::calibctl {
namespace {

TEST(CalibctlStatus, ListsEveryNodeWithItsStates) {
  // GIVEN a drive in quick stop active after a heartbeat loss, one in fault, and an encoder never heard
  const auto json = JsonValue::parse(
      R"j({"ok":true,"state":"failed","progress":0,"nodes":[)j"
      R"j({"winch":0,"role":"drive","node_id":1,"nmt":"operational","configured":true,"cia402":"quick stop active",)j"
      R"j("error_code":"","last_emcy":"0x8130 (life guard or heartbeat error)","emcy_register":17,)j"
      R"j("pdo_age_ms":12.5,"heartbeat_age_ms":40},)j"
      R"j({"winch":1,"role":"drive","node_id":2,"nmt":"operational","configured":true,"cia402":"fault",)j"
      R"j("error_code":"0x8611 (following error)","last_emcy":"0x8611 (following error)","emcy_register":1,)j"
      R"j("pdo_age_ms":3,"heartbeat_age_ms":20},)j"
      R"j({"winch":1,"role":"encoder","node_id":12,"nmt":"unknown","configured":false,"cia402":"","error_code":"",)j"
      R"j("last_emcy":"","emcy_register":0,"pdo_age_ms":null,"heartbeat_age_ms":null}]})j");
  ASSERT_TRUE(json.has_value());
  // WHEN rendered
  const std::string text = render_status(*json);
  // THEN one line per node says it
  EXPECT_NE(text.find("  nodes:\n"
                      "    winch 0 drive 1: operational, quick stop active, last EMCY 0x8130 (life guard or heartbeat "
                      "error), PDO 12 ms ago\n"
                      "    winch 1 drive 2: operational, fault, 0x603F 0x8611 (following error), last EMCY 0x8611 "
                      "(following error), PDO 3 ms ago\n"
                      "    winch 1 encoder 12: unknown (not configured), no PDO yet\n"),
            std::string::npos)
      << text;
}

}  // namespace
}  // namespace cdpr::calibctl
