// calibctl status's text of watch mode (docs/operation.md): the
// state, the last rest's pose from the cables and a stale calibration's finding.
#include <gtest/gtest.h>

#include "calibctl/json_value.h"
#include "calibctl/render.h"

namespace cdpr::calibctl {
namespace {

TEST(CalibctlStatus, WatchModeSaysStaleWithTheFindingAndTheOfferedRefit) {
  // GIVEN the status of a daemon whose health test fired on encoder 1
  const auto json = JsonValue::parse(
      R"j({"ok":true,"state":"idle","progress":0,"nodes":[],"operation":{"mode":"watch",)j"
      R"j("state":"calibration stale","calibration_seq":4,"rests":12,"localized":12,"detail":"at rest",)j"
      R"j("last_problem":"","last_rest":{"rest":12,"age_s":3.2,"position":[120,110,17],)j"
      R"j("position_sigma":[0.002,0.0022,0.0074],"orientation_sigma":[0.001,0.001,0.002],"onboard_sigmas":1.7},)j"
      R"j("finding":{"term":"offset[1]","meaning":"encoder offset slip of cable 1","cable":1,"value":[0.0176],)j"
      R"j("sigma":[0.0033],"since_rest":9,"fired_at_rest":9,"fired_s_ago":40,"rests_fitted":3,)j"
      R"j("calibration_fault":true,"alike":[]},"refit":"kept in pending/ for `calibctl commit`"}})j");
  ASSERT_TRUE(json.has_value());
  // WHEN rendered
  const std::string text = render_status(*json);
  // THEN the watch's lines say what is stale, by how much, and what to do
  EXPECT_NE(text.find("watch: calibration stale (calibration 4), 12 rests, 12 localized from the cables; at rest\n"),
            std::string::npos) << text;
  EXPECT_NE(text.find("last rest 12, 3 s ago: at 120.000, 110.000, 17.000 m, sigma 2.0, 2.2, 7.4 mm"), std::string::npos)
      << text;
  EXPECT_NE(text.find("CALIBRATION STALE: encoder offset slip of cable 1 (offset[1]: 0.0176 +- 0.0033), since rest 9"),
            std::string::npos) << text;
  EXPECT_NE(text.find("re-fit: kept in pending/ for `calibctl commit`"), std::string::npos) << text;
}

TEST(CalibctlStatus, NoWatchLinesWhenNotWatching) {
  const auto json = JsonValue::parse(R"j({"ok":true,"state":"idle","progress":0,"nodes":[],"operation":null})j");
  ASSERT_TRUE(json.has_value());
  EXPECT_EQ(render_status(*json).find("watch:"), std::string::npos);
}

}  // namespace
}  // namespace cdpr::calibctl
