// A real kill: a child process commits and SIGKILLs itself after each step
// of the commit; the parent then opens the store like a restarted daemon and
// must find the old or the new calibration complete, byte for byte.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"
#include "src/store/calibration_store.h"
#include "store_test_support.h"

namespace cdpr::store {
namespace {

using test::calibration_version;
using test::TempStateDir;

TEST(SigkillDuringCommit, RestartedStoreFindsTheOldOrTheNewFileComplete) {
  const std::string old_text = formats::format_calibration_toml(calibration_version(1));
  const std::string new_text = formats::format_calibration_toml(calibration_version(2));
  for (int kill_step = 1; kill_step <= CalibrationStore::kCommitSteps; ++kill_step) {
    SCOPED_TRACE("SIGKILL after step " + std::to_string(kill_step));
    // GIVEN a store with version 1 current
    TempStateDir dir;
    {
      CalibrationStore store({dir.path(), 3});
      ASSERT_TRUE(store.open());
      ASSERT_TRUE(store.commit_text(old_text));
    }
    // WHEN a child process committing version 2 is killed after step kill_step
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      CalibrationStore store({dir.path(), 3});
      store.set_crash_hook([kill_step](int step) {
        if (step == kill_step) ::raise(SIGKILL);
        return false;
      });
      const bool ok = store.open() && store.commit_text(new_text);
      ::_exit(ok ? 0 : 1);
    }
    int wait_status = 0;
    ASSERT_EQ(::waitpid(child, &wait_status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(wait_status) && WTERMSIG(wait_status) == SIGKILL);
    // THEN the restarted store loads version 1 before the rename, version 2 from it on
    CalibrationStore restarted({dir.path(), 3});
    ASSERT_TRUE(restarted.open());
    const auto current = restarted.load_current();
    ASSERT_TRUE(current && current->has_value()) << (current ? "" : current.error().message());
    EXPECT_EQ((*current)->text, kill_step < CalibrationStore::kCommitReplacedStep ? old_text : new_text);
  }
}

}  // namespace
}  // namespace cdpr::store
