// calibctl show's text (tools/calibctl/render.h) of the rejected readings:
// a suspect group's readings are marked as one with its members, a reading
// named alone not.
#include "calibctl/render.h"

#include <gtest/gtest.h>

#include "calibctl/json_value.h"

namespace cdpr::calibctl {
namespace {

std::string show_with(const std::string& rejected) {
  const auto json = JsonValue::parse(R"({"ok":true,"present":true,"seq":2,"winches":[],"fit":{},)"
                                     R"("model_warning":"","rejected":)" + rejected + R"(,"run":null})");
  EXPECT_TRUE(json.has_value());
  return json ? render_show(*json) : std::string();
}

TEST(CalibctlShow, ASuspectGroupIsMarkedAndExplained) {
  // GIVEN a reading named alone and a row whose load cell and encoder 2 are one suspect group
  const std::string members = R"("group_members":"force or encoder cable 2")";
  const std::string text = show_with(R"([{"row":12,"sensor":"encoder","cable":3,"residual":-95.4},)"
                                     R"({"row":24,"sensor":"force","cable":0,"residual":8.2,"group":1,)" + members +
                                     R"(},{"row":24,"sensor":"encoder","cable":2,"residual":6.1,"group":1,)" +
                                     members + "}]");
  // THEN each grouped reading names its group's members, the lone one does not, and the text says what a group is
  const std::string group = "  suspect group: force or encoder cable 2\n";
  EXPECT_NE(text.find("row   24  force                +8.2 sigma" + group), std::string::npos) << text;
  EXPECT_NE(text.find("row   24  encoder cable 2      +6.1 sigma" + group), std::string::npos) << text;
  EXPECT_NE(text.find("row   12  encoder cable 3     -95.4 sigma\n"), std::string::npos) << text;
  EXPECT_NE(text.find("cannot pin on one of its readings"), std::string::npos) << text;
}

TEST(CalibctlShow, ADaemonThatSendsOnlyTheGroupNumberIsStillShown) {
  const std::string text = show_with(R"([{"row":24,"sensor":"force","cable":0,"residual":8.2,"group":1}])");
  EXPECT_NE(text.find("row   24  force                +8.2 sigma  suspect group 1\n"), std::string::npos) << text;
}

TEST(CalibctlShow, ReadingsNamedAloneNeedNoGroupWords) {
  const std::string text = show_with(R"([{"row":12,"sensor":"encoder","cable":3,"residual":-95.4}])");
  EXPECT_NE(text.find("row   12  encoder cable 3     -95.4 sigma\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("suspect group"), std::string::npos) << text;
}

}  // namespace
}  // namespace cdpr::calibctl
