// The daemon calibrating the virtual robot whose load cell is a vendor
// transmitter (FT-11 on RTU, TLU on TCP), configured as an operator would:
// the preset and the indicator's decimal point. The tensions it samples are
// close to the ones the catenary statics predict for each waypoint; with the decimal
// point left out they are 100 times too large and the run stops on the
// tension limit before anything moves.

#include <chrono>
#include <cmath>
#include <thread>

#include "slowdown.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

using virtual_robot::LoadCellModel;

struct Case {
  LoadCellModel model;
  bool rtu;
};

class VendorLoadCellRun : public ::testing::TestWithParam<Case> {};

virtual_robot::VirtualRobotOptions options_for(const Case& c) {
  virtual_robot::VirtualRobotOptions options = large_robot_acceptance_options();
  options.load_cell.model = c.model;
  options.load_cell.unit_id = 17;
  options.modbus_rtu = c.rtu;
  return options;
}

TEST_P(VendorLoadCellRun, SamplesThePredictedTensions) {
  // GIVEN the daemon configured with the transmitter's preset and decimal point (the rig does that)
  VirtualRobotRig rig(options_for(GetParam()));
  EXPECT_EQ(rig.config.load_cell.map.decimals, virtual_robot::kShownDecimals);
  // WHEN a run has sampled three waypoints
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ASSERT_TRUE(rig.ask("start")["ok"].boolean());
  calibctl::JsonValue status;
  const RobotDeadline give_up(rig.robot->clock(), slowed(std::chrono::seconds(90)));
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    status = rig.ask("status");
  } while (status["samples"].integer() < 3 && status["running"].boolean() && !give_up.passed());
  ASSERT_GE(status["samples"].integer(), 3) << status["state"].string() << ": " << status["reason"].string();
  rig.ask("abort");
  rig.stop_daemon();
  // THEN every sampled tension is within 30 % of the statics' prediction
  // (nominal anchors 0.3 m off, estimated offsets and a rest window cut short
  // on a loaded machine leave it some percent off; a wrong unit or decimal
  // point is a factor of 2.2 to 100)
  const int reference = rig.robot->nominal_robot().reference_cable;
  const auto& machine = rig.loop->machine();
  // (a skipped waypoint has no row: the run log pairs rows with waypoints)
  for (const formats::RunWaypoint& waypoint : machine.run_log().waypoints) {
    if (waypoint.sample < 0) continue;
    const Sample& sample = machine.samples()[static_cast<std::size_t>(waypoint.sample)];
    const double predicted_n =
        machine.plan().waypoints[static_cast<std::size_t>(waypoint.index - 1)].rest.tension_n[reference];
    EXPECT_NEAR(sample.force_n, predicted_n, 0.30 * predicted_n) << "waypoint " << waypoint.index;
  }
}

TEST_P(VendorLoadCellRun, AMissingDecimalPointStopsTheRunOnTheTensionLimit) {
  // GIVEN the preset without the indicator's decimal point
  VirtualRobotRig rig(options_for(GetParam()), [](VirtualRobotRig& r) { r.config.load_cell.map.decimals = 0; });
  // WHEN a run starts
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ASSERT_TRUE(rig.ask("start")["ok"].boolean());
  calibctl::JsonValue status;
  const RobotDeadline give_up(rig.robot->clock(), slowed(std::chrono::seconds(30)));
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    status = rig.ask("status");
  } while (status["running"].boolean() && !give_up.passed());
  // THEN it fails on the tension limit, before the first waypoint
  EXPECT_EQ(status["state"].string(), "failed");
  EXPECT_NE(status["reason"].string().find("tension out of limits"), std::string::npos) << status["reason"].string();
  EXPECT_EQ(status["samples"].integer(), 0);
}

INSTANTIATE_TEST_SUITE_P(Vendors, VendorLoadCellRun,
                         ::testing::Values(Case{LoadCellModel::kFlintecFt11, true}, Case{LoadCellModel::kLaumasTlu, false}),
                         [](const auto& info) {
                           return std::string(info.param.model == LoadCellModel::kFlintecFt11 ? "Ft11" : "Tlu") +
                                  (info.param.rtu ? "OnRtu" : "OnTcp");
                         });

}  // namespace
}  // namespace cdpr::integration
