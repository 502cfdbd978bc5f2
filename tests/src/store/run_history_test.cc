// The runs' data in the history: entry layout, listing, the disk budget
// (oldest pruned first, never the current calibration's, a pending fit's or
// a running run's entry), what a crash leaves, and failures that name the
// path.

#include "src/store/run_history.h"

#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "store_test_support.h"
#include "test_broken_directory.h"
#include "../../text_contains.h"

namespace cdpr::store {
namespace {

using test::BrokenDirectory;
using test::file_bytes;
using test::TempStateDir;

using ::cdpr::test::contains;

class Runs {
 public:
  Runs() : history(dir.path() + "/history") { std::filesystem::create_directory(history.dir()); }

  // A finished run with `rows` bytes of samples and, when given, a fit.
  void add(int run, const char* outcome, std::size_t sample_bytes, const std::string& calibration = "") {
    ASSERT_TRUE(history.create(run));
    formats::RunLog log;
    log.run = run;
    log.outcome = outcome;
    log.robot = "large";
    log.started = "2026-11-26T10:00:00Z";
    log.samples = 3;
    log.waypoints.push_back({1, "sampled", 12.5, 0, ""});
    log.waypoints.push_back({2, "skipped", 80.0, -1, "no equilibrium within 60 s"});
    ASSERT_TRUE(history.write(run, RunHistory::kSamplesName, std::string(sample_bytes, 'x')));
    ASSERT_TRUE(history.write(run, RunHistory::kRobotName, "name = \"large\"\n"));
    if (!calibration.empty()) {
      ASSERT_TRUE(history.write(run, RunHistory::kCalibrationName, calibration));
    }
    ASSERT_TRUE(history.write(run, RunHistory::kLogName, formats::format_run_log_toml(log)));
  }

  std::vector<int> listed() const {
    std::vector<int> runs;
    const auto entries = history.entries();
    EXPECT_TRUE(entries);
    if (entries) {
      for (const RunEntry& entry : *entries) runs.push_back(entry.run);
    }
    return runs;
  }

  TempStateDir dir;
  RunHistory history;
};

TEST(RunHistory, EntriesAreDirectoriesOfTheRunsFilesNewestFirst) {
  // GIVEN two runs kept WHEN listed THEN newest first, logs parsed, sizes counted, numbering continues
  Runs r;
  r.add(1, formats::kRunFailed, 100);
  r.add(2, formats::kRunCommitted, 100, "calibration 2\n");
  const auto entries = r.history.entries();
  ASSERT_TRUE(entries);
  ASSERT_EQ(entries->size(), 2u);
  const RunEntry& newest = entries->front();
  EXPECT_EQ(newest.run, 2);
  EXPECT_EQ(newest.path, r.dir.path() + "/history/run-000002");
  EXPECT_TRUE(newest.valid) << newest.problem;
  EXPECT_EQ(newest.log.outcome, "committed");
  ASSERT_EQ(newest.log.waypoints.size(), 2u);
  EXPECT_EQ(newest.log.waypoints[1].why, "no equilibrium within 60 s");
  EXPECT_GT(newest.bytes, 100u);
  EXPECT_EQ(*r.history.next_run(), 3);
  EXPECT_EQ(file_bytes(newest.path + "/calibration.toml"), "calibration 2\n");
}

TEST(RunHistory, PruningRemovesTheOldestRunsUntilTheBudgetHolds) {
  // GIVEN four runs of about 1 kB WHEN pruned to 2.5 kB THEN the two oldest go
  Runs r;
  for (int run = 1; run <= 4; ++run) r.add(run, formats::kRunFailed, 1000);
  const std::uintmax_t each = r.history.entries()->front().bytes;
  const auto removed = r.history.prune(2 * each + each / 2, {});
  ASSERT_TRUE(removed) << removed.error().message();
  EXPECT_EQ(*removed, (std::vector<int>{1, 2}));
  EXPECT_EQ(r.listed(), (std::vector<int>{4, 3}));
  EXPECT_FALSE(std::filesystem::exists(r.history.entry_path(1)));
}

TEST(RunHistory, PruningSparesTheCurrentThePendingAndARunningRun) {
  // GIVEN the oldest run holds the current calibration, the second the pending fit, the newest still runs
  Runs r;
  r.add(1, formats::kRunCommitted, 1000, "current\n");
  r.add(2, formats::kRunFailed, 1000, "pending\n");
  r.add(3, formats::kRunFailed, 1000);
  r.add(4, formats::kRunRunning, 1000);
  // WHEN pruned to a budget of nothing
  const auto removed = r.history.prune(0, {"current\n", "pending\n"});
  // THEN only the unprotected finished run goes
  ASSERT_TRUE(removed) << removed.error().message();
  EXPECT_EQ(*removed, (std::vector<int>{3}));
  EXPECT_EQ(r.listed(), (std::vector<int>{4, 2, 1}));
  ASSERT_TRUE(r.history.find_by_calibration("current\n"));
  EXPECT_EQ(r.history.find_by_calibration("current\n")->run, 1);
  EXPECT_FALSE(r.history.find_by_calibration("other\n"));
}

TEST(RunHistory, AnEntryACrashLeftWithoutLogIsListedWithItsProblemAndPrunable) {
  // GIVEN a run directory made just before a crash (no run.toml)
  Runs r;
  ASSERT_TRUE(r.history.create(1));
  r.add(2, formats::kRunFailed, 10);
  const auto entries = r.history.entries();
  ASSERT_TRUE(entries);
  EXPECT_FALSE(entries->back().valid);
  EXPECT_TRUE(contains(entries->back().problem, "run-000001/run.toml")) << entries->back().problem;
  // WHEN pruned to a budget of nothing THEN it goes like any other older entry
  const auto removed = r.history.prune(0, {});
  ASSERT_TRUE(removed);
  EXPECT_EQ(*removed, (std::vector<int>{1}));
}

TEST(RunHistory, TheNewestRunStaysWhateverTheBudget) {
  // GIVEN two finished runs, the newest failed (the one status names)
  Runs r;
  r.add(1, formats::kRunFailed, 1000);
  r.add(2, formats::kRunFailed, 1000);
  // WHEN pruned to a budget of nothing
  const auto removed = r.history.prune(0, {});
  // THEN the older goes and the newest stays
  ASSERT_TRUE(removed) << removed.error().message();
  EXPECT_EQ(*removed, (std::vector<int>{1}));
  EXPECT_EQ(r.listed(), (std::vector<int>{2}));
}

TEST(RunHistory, RunsLeftRunningBecomeInterruptedAndTheirTempFilesGo) {
  // GIVEN a run a dead daemon left "running" with a half-written temp file, and a finished run
  Runs r;
  r.add(1, formats::kRunCommitted, 10, "c\n");
  r.add(2, formats::kRunRunning, 10);
  std::ofstream(r.history.entry_path(2) + "/.samples.csv.tmp") << "half";
  // WHEN recovered at the next start
  const auto changed = r.history.recover_interrupted("2026-11-26T11:00:00Z", "run interrupted at waypoint 7 of 35");
  // THEN the running one is interrupted with the reason, its data kept; the other is untouched
  ASSERT_TRUE(changed) << changed.error().message();
  EXPECT_EQ(*changed, (std::vector<int>{2}));
  const auto entries = r.history.entries();
  EXPECT_EQ(entries->front().log.outcome, "interrupted");
  EXPECT_EQ(entries->front().log.reason, "run interrupted at waypoint 7 of 35");
  EXPECT_EQ(entries->front().log.finished, "2026-11-26T11:00:00Z");
  EXPECT_EQ(entries->back().log.outcome, "committed");
  EXPECT_FALSE(std::filesystem::exists(r.history.entry_path(2) + "/.samples.csv.tmp"));
  EXPECT_TRUE(std::filesystem::exists(r.history.entry_path(2) + "/samples.csv"));
}

TEST(RunHistory, AWriteThatCannotHappenIsAnErrorNamingThePath) {
  // GIVEN a history directory that cannot be written (a file in its place)
  Runs r;
  BrokenDirectory broken(r.history.dir());
  // WHEN a run's entry is made THEN the error names the path and errno
  const auto made = r.history.create(1);
  ASSERT_FALSE(made);
  EXPECT_TRUE(contains(made.error().message(), r.history.entry_path(1))) << made.error().message();
  const auto written = r.history.write(1, RunHistory::kSamplesName, "x");
  ASSERT_FALSE(written);
  EXPECT_TRUE(contains(written.error().message(), "run-000001")) << written.error().message();
}

}  // namespace
}  // namespace cdpr::store
