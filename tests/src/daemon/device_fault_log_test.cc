// The devices' latched faults reach the daemon's log (the journal under
// systemd) when they appear and when they are reset, once each, not only
// calibctl status.

#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "../store/store_test_support.h"
#include "daemon_on_fakes.h"

namespace cdpr::daemon {
namespace {

using test::DaemonOnFakes;

int count_starting_with(const std::vector<std::string>& log, const std::string& prefix) {
  return static_cast<int>(std::count_if(log.begin(), log.end(),
                                        [&](const std::string& line) { return line.rfind(prefix, 0) == 0; }));
}

void run_steps(DaemonOnFakes& daemon, const DaemonConfig& config, int steps) {
  for (int k = 0; k < steps; ++k) {
    daemon.clock().advance_us(config.loop_period_us);
    daemon.loop().run_once();
  }
}

TEST(DeviceFaultLog, ADriveFaultIsLoggedOnceAndItsResetToo) {
  // GIVEN an idle daemon on fakes
  store::test::TempStateDir dir;
  DaemonConfig config = default_daemon_config();
  config.store.state_dir = dir.path();
  config.control_socket = dir.path() + "/control";
  DaemonOnFakes daemon(config);
  ASSERT_TRUE(daemon.start().ok());
  run_steps(daemon, config, 3);
  EXPECT_EQ(count_starting_with(daemon.log(), "device faults"), 0);
  // WHEN a drive faults and the loop runs on
  daemon.winches().inject_fault(2);
  run_steps(daemon, config, 5);
  // THEN the fault is logged once, naming the winch
  ASSERT_EQ(count_starting_with(daemon.log(), "device faults: winch 2"), 1);
  // AND WHEN the operator resets the faults, that is logged once too
  ASSERT_TRUE(daemon.winches().reset_faults().ok());
  run_steps(daemon, config, 5);
  EXPECT_EQ(count_starting_with(daemon.log(), "device faults cleared"), 1);
}

}  // namespace
}  // namespace cdpr::daemon
