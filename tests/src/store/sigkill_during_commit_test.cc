// A real kill: a child process commits (or rolls back) and SIGKILLs itself
// after one step of it; the parent then opens the store like a restarted
// daemon and checks what a restart must find:
//   * calibration.toml is the old or the new version, byte for byte;
//   * every history entry parses (each was written atomically), the entry
//     of the current file is still there, and so is the previous version;
//   * open() leaves no temp file, and the next commit works and rotates the
//     history back to its depth.
// Steps (src/store/calibration_store.h, atomic_file.h): commit 1-5 history
// entry (half written, written, fsync, rename, dir fsync), 6-10 the same for
// calibration.toml, 11 history rotation (old entries unlinked), 12 history
// dir fsync; rollback 1-5 on calibration.toml. The stores start with a full
// history, so the rotation really deletes an entry.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <random>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "src/formats/calibration_toml.h"
#include "src/store/calibration_store.h"
#include "store_test_support.h"

namespace cdpr::store {
namespace {

using test::calibration_version;
using test::TempStateDir;

constexpr int kDepth = 2;  // history keeps the current plus 2 previous versions

std::string version_text(int version) { return formats::format_calibration_toml(calibration_version(version)); }

// Runs `work` on a fresh store object in a child process that dies by
// SIGKILL from the crash hook at `kill_step`; returns whether it did.
bool killed_in_child(const std::string& dir, int kill_step, const std::function<bool(CalibrationStore&)>& work) {
  const pid_t child = ::fork();
  if (child < 0) return false;
  if (child == 0) {
    CalibrationStore store({dir, kDepth});
    store.set_crash_hook([kill_step](int step) {
      if (step == kill_step) ::raise(SIGKILL);
      return false;
    });
    ::_exit(store.open() && work(store) ? 0 : 1);
  }
  int wait_status = 0;
  return ::waitpid(child, &wait_status, 0) == child && WIFSIGNALED(wait_status) && WTERMSIG(wait_status) == SIGKILL;
}

// What a restarted daemon must find; `expected_current` is the text the
// current file must hold, `must_keep` texts that must still be in history.
void expect_restart_finds(const std::string& dir, const std::string& expected_current,
                          const std::set<std::string>& must_keep) {
  CalibrationStore restarted({dir, kDepth});
  ASSERT_TRUE(restarted.open());
  const auto current = restarted.load_current();
  ASSERT_TRUE(current && current->has_value()) << (current ? "no current file" : current.error().message());
  EXPECT_EQ((*current)->text, expected_current);
  EXPECT_GT((*current)->seq, 0) << "the current file must equal a history entry";
  const auto history = restarted.history();
  ASSERT_TRUE(history) << history.error().message();
  std::set<std::string> kept;
  for (const HistoryEntry& entry : *history) {
    EXPECT_TRUE(entry.valid) << entry.path << ": " << entry.problem;
    kept.insert(test::file_bytes(entry.path));
  }
  for (const std::string& text : must_keep) EXPECT_TRUE(kept.count(text)) << "lost from history:\n" << text;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir)) {
    EXPECT_FALSE(entry.path().filename().string().ends_with(".tmp")) << entry.path();
  }
  // The next commit works and the history rotates back to its depth.
  const std::string next = version_text(99);
  ASSERT_TRUE(restarted.commit_text(next));
  EXPECT_EQ(test::file_bytes(restarted.current_path()), next);
  const auto after = restarted.history();
  ASSERT_TRUE(after);
  EXPECT_EQ(after->size(), static_cast<std::size_t>(kDepth + 1));
}

// A store whose history is full: versions 1..kDepth+1 committed, the newest current.
void fill(const std::string& dir) {
  CalibrationStore store({dir, kDepth});
  ASSERT_TRUE(store.open());
  for (int version = 1; version <= kDepth + 1; ++version) ASSERT_TRUE(store.commit_text(version_text(version)));
}

TEST(SigkillDuringCommit, RestartedStoreFindsTheOldOrTheNewFileCompleteAndTheHistoryIntact) {
  const std::string old_text = version_text(kDepth + 1);
  const std::string new_text = version_text(kDepth + 2);
  for (int kill_step = 1; kill_step <= CalibrationStore::kCommitSteps; ++kill_step) {
    SCOPED_TRACE("SIGKILL after commit step " + std::to_string(kill_step));
    // GIVEN a store with a full history and its newest version current
    TempStateDir dir;
    fill(dir.path());
    // WHEN a child process committing a new version is killed after kill_step
    ASSERT_TRUE(killed_in_child(dir.path(), kill_step, [&](CalibrationStore& store) {
      return static_cast<bool>(store.commit_text(new_text));
    }));
    // THEN the restarted store has the old version before the rename, the new one from it on,
    // AND the previous version is still in the history
    const bool replaced = kill_step >= CalibrationStore::kCommitReplacedStep;
    expect_restart_finds(dir.path(), replaced ? new_text : old_text, {old_text});
  }
}

TEST(SigkillDuringRollback, RestartedStoreFindsTheOldOrTheRolledBackFileComplete) {
  const std::string current_text = version_text(kDepth + 1);
  const std::string target_text = version_text(kDepth);
  for (int kill_step = 1; kill_step <= CalibrationStore::kRollbackSteps; ++kill_step) {
    SCOPED_TRACE("SIGKILL after rollback step " + std::to_string(kill_step));
    // GIVEN a store with a full history and its newest version current
    TempStateDir dir;
    fill(dir.path());
    // WHEN a child process rolling back to the previous version is killed after kill_step
    ASSERT_TRUE(killed_in_child(dir.path(), kill_step, [](CalibrationStore& store) {
      return static_cast<bool>(store.rollback(kDepth));
    }));
    // THEN the restarted store has the newest version before the rename, the rolled-back one from it on,
    // AND both are still in the history
    const bool replaced = kill_step >= CalibrationStore::kRollbackReplacedStep;
    expect_restart_finds(dir.path(), replaced ? target_text : current_text, {current_text, target_text});
  }
}

TEST(SigkillDuringCommit, KillAtAnyMomentOfCommitsAndRollbacksLeavesAConsistentStore) {
  // Kills that land between the hook points too (inside write(), between the
  // unlinks of the rotation): a child commits and rolls back in a loop and is
  // killed after a seeded random delay. Where the kill lands varies with the
  // machine's speed; what must hold afterwards does not.
  std::mt19937 random(20261123);
  std::set<std::string> known;
  for (int version = 1; version <= 40; ++version) known.insert(version_text(version));
  for (int round = 0; round < 20; ++round) {
    SCOPED_TRACE("round " + std::to_string(round));
    // GIVEN a store with a full history
    TempStateDir dir;
    fill(dir.path());
    // WHEN a child committing versions and rolling back is killed at an arbitrary moment
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      CalibrationStore store({dir.path(), kDepth});
      if (!store.open()) ::_exit(1);
      for (int version = kDepth + 2; version <= 40; ++version) {
        if (!store.commit_text(version_text(version))) ::_exit(1);
        if (version % 3 == 0 && !store.rollback(version - 1)) ::_exit(1);
      }
      ::_exit(0);
    }
    ::usleep(static_cast<useconds_t>(random() % 20000));
    ::kill(child, SIGKILL);
    int wait_status = 0;
    ASSERT_EQ(::waitpid(child, &wait_status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(wait_status) || (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) == 0));
    // THEN the current file is one of the versions, complete, and equals a valid history entry
    CalibrationStore restarted({dir.path(), kDepth});
    ASSERT_TRUE(restarted.open());
    const auto current = restarted.load_current();
    ASSERT_TRUE(current && current->has_value()) << (current ? "no current file" : current.error().message());
    EXPECT_TRUE(known.count((*current)->text)) << (*current)->text;
    EXPECT_GT((*current)->seq, 0);
    const auto history = restarted.history();
    ASSERT_TRUE(history);
    for (const HistoryEntry& entry : *history) EXPECT_TRUE(entry.valid) << entry.path << ": " << entry.problem;
    ASSERT_TRUE(restarted.commit_text(version_text(99)));
  }
}

}  // namespace
}  // namespace cdpr::store
