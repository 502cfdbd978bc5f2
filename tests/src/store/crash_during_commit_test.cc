// Kill-point tests: a commit or rollback stopped after every one of its
// steps leaves calibration.toml either the old or the new content, complete,
// and a reopened store loads it.

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"
#include "src/store/calibration_store.h"
#include "store_test_support.h"

namespace cdpr::store {
namespace {

using test::calibration_version;
using test::file_bytes;
using test::TempStateDir;

TEST(CrashDuringCommit, EveryStepLeavesTheOldOrTheNewFileComplete) {
  const std::string old_text = formats::format_calibration_toml(calibration_version(1));
  const std::string new_text = formats::format_calibration_toml(calibration_version(2));
  for (int crash_step = 1; crash_step <= CalibrationStore::kCommitSteps; ++crash_step) {
    SCOPED_TRACE("crash after step " + std::to_string(crash_step));
    // GIVEN a store with version 1 current
    TempStateDir dir;
    CalibrationStore store({dir.path(), 3});
    ASSERT_TRUE(store.open());
    ASSERT_TRUE(store.commit_text(old_text));
    // WHEN committing version 2 is killed after step crash_step
    store.set_crash_hook([crash_step](int step) { return step == crash_step; });
    const auto committed = store.commit_text(new_text);
    ASSERT_FALSE(committed);
    EXPECT_EQ(committed.error().operation, "crash");
    // THEN a reopened store sees version 1 before the rename and version 2 from it on, byte for byte
    CalibrationStore reopened({dir.path(), 3});
    ASSERT_TRUE(reopened.open());
    const auto current = reopened.load_current();
    ASSERT_TRUE(current && current->has_value()) << (current ? "" : current.error().message());
    EXPECT_EQ((*current)->text, crash_step < CalibrationStore::kCommitReplacedStep ? old_text : new_text);
    // AND no temp file survives the reopen, and the next commit works
    ASSERT_TRUE(reopened.commit(calibration_version(3)));
    EXPECT_EQ(file_bytes(reopened.current_path()), formats::format_calibration_toml(calibration_version(3)));
  }
}

TEST(CrashDuringRollback, EveryStepLeavesTheOldOrTheNewFileComplete) {
  const std::string first = formats::format_calibration_toml(calibration_version(1));
  const std::string second = formats::format_calibration_toml(calibration_version(2));
  for (int crash_step = 1; crash_step <= CalibrationStore::kRollbackSteps; ++crash_step) {
    SCOPED_TRACE("crash after step " + std::to_string(crash_step));
    // GIVEN versions 1 and 2, with 2 current
    TempStateDir dir;
    CalibrationStore store({dir.path(), 3});
    ASSERT_TRUE(store.open());
    ASSERT_TRUE(store.commit_text(first));
    ASSERT_TRUE(store.commit_text(second));
    // WHEN the rollback to 1 is killed after step crash_step
    store.set_crash_hook([crash_step](int step) { return step == crash_step; });
    ASSERT_FALSE(store.rollback(1));
    // THEN the current file is version 2 before the rename, version 1 after it
    CalibrationStore reopened({dir.path(), 3});
    ASSERT_TRUE(reopened.open());
    EXPECT_EQ(file_bytes(reopened.current_path()), crash_step < CalibrationStore::kRollbackReplacedStep ? second : first);
  }
}

}  // namespace
}  // namespace cdpr::store
