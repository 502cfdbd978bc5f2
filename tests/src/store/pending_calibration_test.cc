// Nothing lost: the store proves it can write before a run, keeps a fit
// whose commit failed in pending/ and commits it once the cause is fixed,
// and says which stored files are unreadable. The failures are made with a
// file where a directory should be, which stops root as well.

#include "src/store/pending_calibration.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"
#include "store_test_support.h"
#include "test_broken_directory.h"
#include "../../text_contains.h"

namespace cdpr::store {
namespace {

using test::BrokenDirectory;
using test::calibration_version;
using test::file_bytes;
using test::TempStateDir;

using ::cdpr::test::contains;

class StoreWithHistory {
 public:
  StoreWithHistory() : store({dir.path(), 5}) {
    EXPECT_TRUE(store.open());
    EXPECT_TRUE(store.commit(calibration_version(1)));
  }
  TempStateDir dir;
  CalibrationStore store;
};

TEST(StoreProbe, AWritableStorePassesAndLeavesNothingBehind) {
  // GIVEN a healthy store WHEN probed THEN it passes and no probe file is left
  StoreWithHistory s;
  const auto probed = s.store.probe_writable();
  ASSERT_TRUE(probed) << probed.error().message();
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(s.store.history_dir()), {}), 1);
  EXPECT_FALSE(std::filesystem::exists(s.dir.path() + "/.write-probe.tmp"));
}

TEST(StoreProbe, AHistoryDirectoryThatCannotBeWrittenFailsNamingIt) {
  // GIVEN a store whose history directory cannot take files
  StoreWithHistory s;
  BrokenDirectory broken(s.store.history_dir());
  // WHEN probed THEN it fails, naming the probe file in that directory and the reason
  const auto probed = s.store.probe_writable();
  ASSERT_FALSE(probed);
  EXPECT_TRUE(contains(probed.error().message(), s.store.history_dir() + "/.write-probe.tmp"))
      << probed.error().message();
  EXPECT_TRUE(contains(probed.error().message(), "Not a directory")) << probed.error().message();
}

TEST(PendingCalibration, AFitKeptAfterAFailedCommitIsCommittedOnceTheCauseIsFixed) {
  // GIVEN a store whose commit fails, and the fit and samples kept in pending/
  StoreWithHistory s;
  const std::string before = file_bytes(s.store.current_path());
  const PendingCalibration pending(s.dir.path());
  {
    BrokenDirectory broken(s.store.history_dir());
    ASSERT_FALSE(s.store.commit(calibration_version(2)));
    ASSERT_TRUE(pending.keep(calibration_version(2), "sample,x\n0,1\n"));
    // AND a retry while the cause is still there fails and keeps them
    ASSERT_FALSE(pending.commit_into(s.store));
    EXPECT_TRUE(pending.exists());
    EXPECT_EQ(file_bytes(s.store.current_path()), before);
  }
  EXPECT_EQ(file_bytes(pending.dir() + "/samples.csv"), "sample,x\n0,1\n");
  // WHEN the cause is fixed and the pending fit committed
  const auto committed = pending.commit_into(s.store);
  // THEN it is the current calibration, as the next version, and pending/ is gone
  ASSERT_TRUE(committed) << committed.error().message();
  EXPECT_EQ(*committed, 2);
  EXPECT_EQ(file_bytes(s.store.current_path()), formats::format_calibration_toml(calibration_version(2)));
  EXPECT_FALSE(pending.exists());
  EXPECT_FALSE(std::filesystem::exists(pending.dir()));
  // AND with nothing pending a commit says so
  const auto nothing = pending.commit_into(s.store);
  ASSERT_FALSE(nothing);
  EXPECT_EQ(nothing.error().errno_value, ENOENT);
}

TEST(StoreProblems, ATruncatedCurrentFileAndAnUnreadableHistoryEntryAreNamed) {
  // GIVEN a store with two versions, then calibration.toml cut in half and entry 1 emptied
  StoreWithHistory s;
  ASSERT_TRUE(s.store.commit(calibration_version(2)));
  EXPECT_TRUE(s.store.problems().empty());
  const std::string text = file_bytes(s.store.current_path());
  std::ofstream(s.store.current_path(), std::ios::trunc) << text.substr(0, text.size() / 2);
  std::ofstream(s.store.history_dir() + "/" + CalibrationStore::history_name(1), std::ios::trunc) << "";
  // WHEN the store is checked
  const std::vector<std::string> problems = s.store.problems();
  // THEN both are named, the current file first
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_TRUE(contains(problems[0], "the current calibration is unreadable")) << problems[0];
  EXPECT_TRUE(contains(problems[0], s.store.current_path())) << problems[0];
  EXPECT_TRUE(contains(problems[1], "history entry 1 is unreadable")) << problems[1];
}

}  // namespace
}  // namespace cdpr::store
