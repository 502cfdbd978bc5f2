// A really read-only store (a read-only bind mount in the daemon's own mount
// namespace: EROFS, which holds for root too), with the real daemon against
// the virtual robot: read-only from the start, the run is refused in
// preflight before anything moves; turning read-only during the run, the
// run stops at its next write of the run's data (full_disk_test.cc keeps a
// fit whose commit fails and commits it once space is back).
// Skipped where mount namespaces are not allowed.

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "slowdown.h"
#include "virtual_robot_process.h"
#include "../text_contains.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

bool mount_namespaces_allowed() { return std::system("unshare -m --propagation private true 2>/dev/null") == 0; }

// Runs the daemon in a new mount namespace where `dir` is bind-mounted onto
// itself (read-only when `read_only`), so it can be remounted from outside
// with nsenter without touching anybody else's view.
std::vector<std::string> in_own_mount_namespace(const std::string& dir, bool read_only) {
  std::string script = "mount --bind '" + dir + "' '" + dir + "'";
  if (read_only) script += " && mount -o remount,bind,ro '" + dir + "'";
  return {"unshare", "-m", "--propagation", "private", "sh", "-c", script + " && exec \"$0\" \"$@\""};
}

// A read-only remount is refused (EBUSY) while the daemon's run recorder has
// a file of the history open for writing; each write is short, so a few
// tries a moment apart find it closed.
bool remount(pid_t pid, const std::string& dir, const char* mode) {
  const std::string command =
      "nsenter -t " + std::to_string(pid) + " -m mount -o remount,bind," + mode + " '" + dir + "'";
  constexpr int kTries = 50;
  for (int attempt = 1; attempt < kTries; ++attempt) {
    if (std::system((command + " 2>/dev/null").c_str()) == 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return std::system(command.c_str()) == 0;
}

using ::cdpr::test::contains;

TEST(ReadOnlyStore, ReadOnlyFromTheStartTheRunIsRefusedBeforeAnythingMoves) {
  if (!mount_namespaces_allowed()) GTEST_SKIP() << "mount namespaces are not allowed here";
  // GIVEN a daemon whose history directory is mounted read-only
  VirtualRobotProcess rig;
  const std::string history = rig.state_dir + "/history";
  std::filesystem::create_directories(history);
  auto daemon = rig.start_daemon("daemon", in_own_mount_namespace(history, true));
  ASSERT_TRUE(wait_until([&] { return rig.answers(); }, slowed(30s))) << daemon->log();
  std::this_thread::sleep_for(1s);
  // WHEN a calibration is started
  ASSERT_TRUE(rig.ask("start")["ok"].boolean());
  const calibctl::JsonValue status = rig.wait_for_end(slowed(60s));
  // THEN it fails in preflight, saying the store cannot be written and why
  EXPECT_EQ(status["state"].string(), "failed");
  const std::string reason = status["reason"].string();
  std::printf("reason: %s\n", reason.c_str());
  EXPECT_TRUE(contains(reason, "the store cannot be written (open " + history +
                                   "/.write-probe.tmp: Read-only file system)"))
      << reason;
  EXPECT_TRUE(contains(reason, "(during preflight)")) << reason;
  EXPECT_EQ(status["waypoints"].integer(), 0);  // nothing was planned, nothing moved
}

TEST(ReadOnlyStore, TurningReadOnlyMidRunStopsTheRunAtItsNextWrite) {
  if (!mount_namespaces_allowed()) GTEST_SKIP() << "mount namespaces are not allowed here";
  // GIVEN a short run (12 waypoints, the large robot) of a daemon in its own mount namespace
  VirtualRobotProcess rig("large", 12,
                          "[validation]\nmin_samples = 10\nmax_anchor_sigma = 1.0\nmax_offset_sigma = 1.0\n");
  const std::string history = rig.state_dir + "/history";
  std::filesystem::create_directories(history);
  auto daemon = rig.start_daemon("daemon", in_own_mount_namespace(history, false));
  ASSERT_TRUE(wait_until([&] { return rig.answers(); }, slowed(30s))) << daemon->log();
  std::this_thread::sleep_for(1s);
  ASSERT_TRUE(rig.ask("start")["ok"].boolean());
  ASSERT_TRUE(rig.wait_until_robot([&] { return rig.ask("status")["waypoint"].integer() >= 2; }, slowed(60s)))
      << daemon->log();
  // WHEN the history directory becomes read-only after preflight
  ASSERT_TRUE(remount(daemon->pid(), history, "ro"));
  const calibctl::JsonValue at_remount = rig.ask("status");
  const calibctl::JsonValue status = rig.wait_for_end(slowed(240s));
  // THEN the run stops at its next write of the run's data (not at its
  // commit), naming the file and the errno; nothing is committed
  const std::string reason = status["reason"].string();
  std::printf("reason: %s\n", reason.c_str());
  ASSERT_EQ(status["state"].string(), "failed") << reason;
  EXPECT_TRUE(contains(reason, "Read-only file system: the run's data cannot be kept")) << reason;
  EXPECT_LE(status["samples"].integer(), at_remount["samples"].integer() + 1) << reason;
  EXPECT_FALSE(std::filesystem::exists(rig.state_dir + "/calibration.toml"));
  // AND `calibctl commit` says why there is nothing to commit
  ChildProcess refused({built_program("tools/calibctl/calibctl"), "--socket", rig.socket, "commit"},
                       rig.dir + "/commit-refused.log");
  EXPECT_EQ(refused.wait_exit(slowed(30s)), std::optional<int>(1)) << refused.log();
  EXPECT_TRUE(contains(refused.log(), "nothing to commit")) << refused.log();
  EXPECT_TRUE(contains(refused.log(), "Read-only file system")) << refused.log();
}

}  // namespace
}  // namespace cdpr::integration
