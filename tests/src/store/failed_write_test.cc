// A write that fails for want of space leaves nothing behind: no temp file,
// the old file as it was, the error naming the path and the errno. The
// process's file size limit (RLIMIT_FSIZE, EFBIG) stands in for a full disk
// here: the write fails after open() as ENOSPC does.
// (tests/integration/full_disk_test.cc fills a real tmpfs.)

#include <sys/resource.h>

#include <csignal>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "src/store/atomic_file.h"
#include "store_test_support.h"
#include "../../text_contains.h"

namespace cdpr::store {
namespace {

using ::cdpr::test::contains;
using test::file_bytes;
using test::TempStateDir;

// Files may not grow beyond `bytes` while it lives (SIGXFSZ ignored, so
// the write fails with EFBIG instead of killing the test).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    getrlimit(RLIMIT_FSIZE, &old_);
    rlimit limit = old_;
    limit.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
};

TEST(FailedWrite, AWriteThatRunsOutOfSpaceLeavesNoTempFileAndTheOldFileIntact) {
  // GIVEN a small file in place, and no room for a bigger one
  TempStateDir dir;
  ASSERT_TRUE(write_file_atomically(dir.path(), "samples.csv", "row 1\n", {}, 1));
  const FileSizeLimit limit(64);
  // WHEN a bigger version is written
  const auto written = write_file_atomically(dir.path(), "samples.csv", std::string(1000, 'x'), {}, 1);
  // THEN it fails naming the temp file and the errno, the temp file is gone and the old content stays
  ASSERT_FALSE(written);
  EXPECT_TRUE(contains(written.error().message(), "write " + dir.path() + "/.samples.csv.tmp: File too large"))
      << written.error().message();
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/.samples.csv.tmp"));
  EXPECT_EQ(file_bytes(dir.path() + "/samples.csv"), "row 1\n");
}

TEST(FailedWrite, ASimulatedCrashStillLeavesItsTempFileAsAKillWould) {
  // GIVEN a write stopped after its first half as by a kill
  TempStateDir dir;
  const auto written =
      write_file_atomically(dir.path(), "run.toml", "outcome = \"running\"\n", [](int step) { return step == 1; }, 1);
  // THEN the temp file stays for open()'s clean-up, as a real crash leaves it
  ASSERT_FALSE(written);
  EXPECT_TRUE(std::filesystem::exists(dir.path() + "/.run.toml.tmp"));
}

}  // namespace
}  // namespace cdpr::store
