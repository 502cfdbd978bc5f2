// What a daemon says at start about the store it finds: a truncated
// calibration.toml and an unreadable history entry are reported in its
// status (calibctl status) from the first request on, and a fit a failed
// commit kept is announced.

#include <fstream>

#include <gtest/gtest.h>

#include "../store/store_test_support.h"
#include "daemon_on_fakes.h"
#include "src/store/pending_calibration.h"

namespace cdpr::daemon {
namespace {

using test::DaemonOnFakes;

TEST(StartReport, ATruncatedCalibrationAndAPendingFitAreReportedFromTheStart) {
  // GIVEN a state directory with two versions, calibration.toml cut short and a kept fit
  store::test::TempStateDir dir;
  {
    store::CalibrationStore store({dir.path(), 5});
    ASSERT_TRUE(store.open());
    ASSERT_TRUE(store.commit(store::test::calibration_version(1)));
    ASSERT_TRUE(store.commit(store::test::calibration_version(2)));
    const std::string text = store::test::file_bytes(store.current_path());
    std::ofstream(store.current_path(), std::ios::trunc) << text.substr(0, text.size() / 2);
    ASSERT_TRUE(store::PendingCalibration(dir.path()).keep(store::test::calibration_version(3), "sample\n"));
  }
  DaemonConfig config = default_daemon_config();
  config.store.state_dir = dir.path();
  config.control_socket = dir.path() + "/control";
  // WHEN a daemon starts there
  DaemonOnFakes daemon(config);
  ASSERT_TRUE(daemon.start().ok());
  // THEN its status names the unreadable current calibration and the pending fit
  const calibration::CalibrationStatus& status = daemon.loop().machine().status();
  ASSERT_EQ(status.store_problems.size(), 1u);
  EXPECT_NE(status.store_problems[0].find("the current calibration is unreadable (parse " + dir.path() +
                                          "/calibration.toml"),
            std::string::npos)
      << status.store_problems[0];
  EXPECT_TRUE(status.pending_commit);
}

}  // namespace
}  // namespace cdpr::daemon
