// The full field calibration against the virtual robot whose CANopen nodes
// play a vendor quirk profile (docs/fieldbus.md, "Vendor quirks"), each a
// shipped EDS file: 2-TPDO encoders, COB-ID bit 30 held at 1, no
// transmission type 255, drives in rpm. The daemon, configured as for any
// robot with the EDS files the nodes play (plus the winches' mechanics),
// must configure every node and commit a calibration whose anchors are
// within 0.10 m of the truth, as FullCalibration's acceptance run does with
// the profiles' defaults. One calibration per quirk, of 12 waypoints: the
// quirks act in the configuration and in every move, and four 35-waypoint
// runs would cost CI's sanitizer stage some 20 minutes.

#include <chrono>
#include <thread>

#include "slowdown.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

class VendorCanopenRun : public ::testing::TestWithParam<std::string> {};

TEST_P(VendorCanopenRun, CalibratesTheLargeRobotWithin10cm) {
  // GIVEN the acceptance robot whose nodes play the quirk, and the daemon with its shipped defaults
  virtual_robot::VirtualRobotOptions options = large_robot_acceptance_options();
  std::string error;
  const auto quirks = virtual_robot::parse_canopen_quirks(GetParam(), error);
  ASSERT_TRUE(quirks) << error;
  virtual_robot::CanopenNodes::apply(*quirks, options.nodes);
  VirtualRobotRig rig(options, [&quirks](VirtualRobotRig& r) {
    r.config.calibrator.planner.waypoint_count = 12;
    r.config.winches.drive.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/" + quirks->drive_eds;
    r.config.winches.encoder.eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/" + quirks->encoder_eds;
  });

  // WHEN the operator starts a calibration and it runs to its end
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ASSERT_TRUE(rig.ask("start")["ok"].boolean()) << rig.ask("status")["reason"].string();
  const RobotDeadline give_up(rig.robot->clock(), slowed(std::chrono::minutes(5)));
  calibctl::JsonValue status = rig.ask("status");
  while (status["running"].boolean() && !give_up.passed()) {
    std::this_thread::sleep_for(std::chrono::seconds(1));
    status = rig.ask("status");
  }
  rig.loop->wait_for_history();
  rig.stop_daemon();
  rig.keep_dir = true;

  // THEN it committed from every waypoint, each anchor within 0.10 m of the truth
  ASSERT_EQ(status["state"].string(), "done") << status["reason"].string() << " (in " << rig.dir << ")";
  EXPECT_EQ(status["samples"].integer(), rig.config.calibrator.planner.waypoint_count);
  const auto current = rig.store->load_current();
  ASSERT_TRUE(current && current->has_value());
  const Calibration& calibration = (*current)->calibration;
  const Truth& truth = rig.robot->truth();
  for (int i = 0; i < kCableCount; ++i) {
    const double error_m = (calibration.winches[i].anchor_world - truth.winches[i].anchor_world).norm();
    std::printf("%s: cable %d anchor error %.4f m\n", GetParam().c_str(), i, error_m);
    EXPECT_LT(error_m, 0.10) << "cable " << i;
  }
  rig.keep_dir = ::testing::Test::HasFailure();
}

INSTANTIATE_TEST_SUITE_P(Quirks, VendorCanopenRun,
                         ::testing::ValuesIn(virtual_robot::canopen_quirk_names()),
                         [](const auto& info) {
                           std::string name;
                           for (const char c : info.param) {
                             if (c != '-') name += c;
                           }
                           return name;
                         });

}  // namespace
}  // namespace cdpr::integration
