// The hardware monitor's handling of the load cell behind a reader that
// returns its latest reading without waiting: a reading returned again is
// not new, errors before the first reading are left to preflight's
// first-contact wait and then named, errors after it count as before.

#include "src/calibration/hardware_monitor.h"

#include <gtest/gtest.h>

#include "../../fakes/fake_load_cell.h"
#include "../../fakes/fake_pose_source.h"
#include "../../fakes/fake_winch_bank.h"
#include "../../fakes/manual_clock.h"

namespace cdpr::calibration {
namespace {

struct MonitorRig {
  MonitorRig() : load_cell(clock), pose(clock), monitor(winches, load_cell, pose, MonitorLimits{}) {
    EXPECT_TRUE(winches.open().ok());
    EXPECT_TRUE(load_cell.open().ok());
    EXPECT_TRUE(pose.open().ok());
  }
  fakes::ManualClock clock{5'000'000};
  fakes::FakeWinchBank winches;
  fakes::FakeLoadCell load_cell;
  fakes::FakePoseSource pose;
  HardwareMonitor monitor;
};

TEST(HardwareMonitor, AReadingReturnedAgainIsNotNew) {
  // GIVEN a load cell whose reading carries the time it arrived
  MonitorRig rig;
  rig.load_cell.set_tension(300.0);
  // WHEN polled twice at the same time THEN the first reading is new, the same one again is not
  EXPECT_EQ(rig.monitor.poll(rig.clock.now_us()), "");
  EXPECT_TRUE(rig.monitor.readings().tension_is_new);
  EXPECT_EQ(rig.monitor.poll(rig.clock.now_us()), "");
  EXPECT_FALSE(rig.monitor.readings().tension_is_new);
  // WHEN a newer one arrives THEN it is new
  rig.clock.advance_ms(20);
  EXPECT_EQ(rig.monitor.poll(rig.clock.now_us()), "");
  EXPECT_TRUE(rig.monitor.readings().tension_is_new);
}

TEST(HardwareMonitor, ErrorsBeforeTheFirstReadingAreNamedNotCounted) {
  // GIVEN a load cell that has not answered yet
  MonitorRig rig;
  rig.load_cell.fail_always(hal::Status(hal::ErrorCode::kTimeout, "load cell: no reading yet"));
  // WHEN polled more often than the tolerance of failed reads
  for (int i = 0; i < 10; ++i) EXPECT_EQ(rig.monitor.poll(rig.clock.now_us()), "") << i;
  // THEN it is only not heard from yet, and the check names the cause
  EXPECT_NE(rig.monitor.not_yet_heard().find("load cell"), std::string::npos);
  EXPECT_NE(rig.monitor.check(rig.clock.now_us(), false).find("load cell: no reading yet (timeout: load cell: no reading yet)"),
            std::string::npos)
      << rig.monitor.check(rig.clock.now_us(), false);
  // WHEN it answers and then fails past the tolerance THEN that is a fault
  rig.load_cell.fail_always(hal::Status::Ok());
  rig.load_cell.set_tension(300.0);
  EXPECT_EQ(rig.monitor.poll(rig.clock.now_us()), "");
  rig.load_cell.fail_always(hal::Status(hal::ErrorCode::kTimeout, "load cell: silent"));
  std::string fault;
  for (int i = 0; i < 4 && fault.empty(); ++i) fault = rig.monitor.poll(rig.clock.now_us());
  EXPECT_NE(fault.find("4 failed reads in a row"), std::string::npos) << fault;
}

}  // namespace
}  // namespace cdpr::calibration
