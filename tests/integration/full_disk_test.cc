// A full disk, really: the daemon's state directory is a small tmpfs in the
// daemon's own mount namespace, filled from outside (nsenter) at chosen
// points of a run against the virtual robot (large preset, 12 waypoints, as ReadOnlyStore):
//   - at its solve, before the commit: the run fails within one write, the
//     old calibration (none here) stays, the fit is kept in memory (pending/
//     cannot be written either), and once space is freed `calibctl commit`
//     commits it;
//   - at waypoint 2 and at waypoint 5: the run fails within one write (no
//     further waypoint is measured), calibration.toml stays as it was,
//     run.toml counts what samples.csv holds, no temp file is left, and
//     `calibctl commit` says why there is nothing to commit.
// Prints the figures of issue 34's acceptance. Skipped where mount
// namespaces are not allowed.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include "slowdown.h"
#include "src/formats/run_log_toml.h"
#include "src/formats/samples_csv.h"
#include "virtual_robot_process.h"
#include "../text_contains.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;
using ::cdpr::test::contains;

bool tmpfs_mounts_allowed() { return std::system("unshare -m --propagation private true 2>/dev/null") == 0; }

// The daemon in a new mount namespace where `dir` is a tmpfs of `size`.
std::vector<std::string> on_small_tmpfs(const std::string& dir, const std::string& size) {
  const std::string script = "mkdir -p '" + dir + "' && mount -t tmpfs -o size=" + size + " tmpfs '" + dir + "'";
  return {"unshare", "-m", "--propagation", "private", "sh", "-c", script + " && exec \"$0\" \"$@\""};
}

class SmallDisk {
 public:
  SmallDisk(pid_t daemon, std::string dir) : daemon_(daemon), dir_(std::move(dir)) {}
  // Fills what is left of the tmpfs (as the daemon sees it).
  void fill() const { in_namespace("dd if=/dev/zero of='" + dir_ + "/filler' bs=4096 2>/dev/null; true"); }
  void free_space() const { in_namespace("rm -f '" + dir_ + "/filler'"); }
  // A file of the daemon's view (its mount namespace's root, through /proc).
  std::string path(const std::string& file) const {
    return "/proc/" + std::to_string(daemon_) + "/root" + dir_ + "/" + file;
  }
  std::string bytes(const std::string& file) const {
    std::ifstream in(path(file), std::ios::binary);
    if (!in) return "<absent>";
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  // Temp files (".<name>.tmp") anywhere in the state directory.
  std::vector<std::string> temp_files() const {
    std::vector<std::string> found;
    std::error_code error;
    for (const auto& entry : std::filesystem::recursive_directory_iterator(path(""), error)) {
      const std::string name = entry.path().filename().string();
      if (name.front() == '.' && name.ends_with(".tmp")) found.push_back(entry.path().string());
    }
    return found;
  }

 private:
  void in_namespace(const std::string& command) const {
    const std::string line = "nsenter -t " + std::to_string(daemon_) + " -m sh -c \"" + command + "\"";
    EXPECT_EQ(std::system(line.c_str()), 0) << line;
  }
  pid_t daemon_;
  std::string dir_;
};

// Asks for the status as fast as the daemon answers until `done`.
calibctl::JsonValue poll_until(const VirtualRobotProcess& rig, const std::function<bool(const calibctl::JsonValue&)>& done,
                               std::chrono::seconds timeout) {
  calibctl::JsonValue status;
  const RobotDeadline end(rig.robot_clock(), timeout);
  while (!end.passed()) {
    status = rig.ask("status");
    if (done(status)) return status;
    std::this_thread::sleep_for(10ms);
  }
  return status;
}

// The run's end after the disk is filled now: it must fail for want of space.
struct AfterFill {
  calibctl::JsonValue end;
  double seconds = 0.0;  // from the fill to the failed state seen, in the robot's time
  std::string reason;
};
AfterFill fill_and_wait_for_end(const VirtualRobotProcess& rig, const SmallDisk& disk) {
  const hal::TimeUs filled_us = rig.robot_clock().now_us();
  disk.fill();
  AfterFill after;
  after.end = rig.wait_for_end(slowed(120s));
  after.seconds = 1e-3 * robot_ms_since(rig.robot_clock(), filled_us);
  after.reason = after.end["reason"].string();
  EXPECT_EQ(after.end["state"].string(), "failed") << after.reason;
  EXPECT_TRUE(contains(after.reason, "No space left on device")) << after.reason;
  return after;
}

std::string calibctl_commit(const VirtualRobotProcess& rig, const std::string& name, int& exit_code) {
  ChildProcess calibctl({built_program("tools/calibctl/calibctl"), "--socket", rig.socket, "commit"},
                        rig.dir + "/" + name + ".log");
  exit_code = calibctl.wait_exit(slowed(30s)).value_or(-1);
  return calibctl.log();
}

// Fills the disk once the run is at `waypoint`, then checks that the run
// stopped within one write and that nothing was half-written.
void fill_at_waypoint(const VirtualRobotProcess& rig, const SmallDisk& disk, int waypoint, int run,
                      const std::string& calibration_before) {
  ASSERT_TRUE(rig.ask("start")["ok"].boolean());
  const calibctl::JsonValue at = poll_until(
      rig, [&](const calibctl::JsonValue& s) { return s["waypoint"].integer() >= waypoint || !s["running"].boolean(); },
      slowed(120s));
  ASSERT_EQ(at["waypoint"].integer(), waypoint) << at["reason"].string();
  const int samples_at_fill = at["samples"].integer();
  // THEN the run failed at the first write after the fill (the sample of this
  // waypoint, or the marker of the next), naming the path and errno
  const auto [end, stopped_s, reason] = fill_and_wait_for_end(rig, disk);
  EXPECT_TRUE(contains(reason, "the run's data cannot be kept")) << reason;
  EXPECT_LE(end["samples"].integer(), samples_at_fill + 1) << reason;
  EXPECT_LE(end["waypoint"].integer(), waypoint + 1) << reason;
  // AND the old calibration is intact byte for byte, no temp file is left
  EXPECT_EQ(disk.bytes("calibration.toml"), calibration_before);
  EXPECT_TRUE(disk.temp_files().empty()) << disk.temp_files().front();
  // AND run.toml counts what samples.csv holds
  char entry[32];
  std::snprintf(entry, sizeof entry, "history/run-%06d/", run);
  const auto log = formats::read_run_log_toml(disk.path(std::string(entry) + "run.toml"));
  const auto rows = formats::read_samples_csv(disk.path(std::string(entry) + "samples.csv"), kCableCount);
  ASSERT_TRUE(log) << log.error().message();
  ASSERT_TRUE(rows) << rows.error().message();
  EXPECT_EQ(log->samples, static_cast<int>(rows->size()));
  std::printf("disk full at waypoint %d: run %s %.2f s after the fill at waypoint %d (%d samples then; stopped at "
              "waypoint %d with %d samples); calibration.toml %s; run.toml outcome %s, %d samples = %zu rows of "
              "samples.csv; temp files left: %zu\nreason: %s\n",
              waypoint, end["state"].string().c_str(), stopped_s, waypoint, samples_at_fill,
              end["waypoint"].integer(), end["samples"].integer(),
              disk.bytes("calibration.toml") == calibration_before ? "intact" : "CHANGED", log->outcome.c_str(),
              log->samples, rows->size(), disk.temp_files().size(), reason.c_str());
  // AND WHEN space is back THEN `calibctl commit` says exactly why there is nothing to commit
  disk.free_space();
  int exit_code = 0;
  const std::string answer = calibctl_commit(rig, "commit-after-waypoint-" + std::to_string(waypoint), exit_code);
  EXPECT_EQ(exit_code, 1) << answer;
  EXPECT_TRUE(contains(answer, "nothing to commit")) << answer;
  EXPECT_TRUE(contains(answer, "the last run: failed: store:")) << answer;
  std::printf("calibctl commit after freeing space: %s", answer.c_str());
}

// The daemon (12 waypoints a run, the large robot, as ReadOnlyStore) on a
// 2 MB tmpfs of its own; stopped with SIGTERM at the end, which must exit 0.
struct DaemonOnSmallDisk {
  DaemonOnSmallDisk()
      : rig("large", 12,
            "[validation]\nmin_samples = 10\nmax_anchor_sigma = 1.0\nmax_offset_sigma = 1.0\n"
            "[history]\nmodel_check = false\n"),
        daemon(rig.start_daemon("daemon", on_small_tmpfs(rig.state_dir, "2m"))),
        disk(daemon->pid(), rig.state_dir),
        answers(wait_until([&] { return rig.answers(); }, slowed(30s))) {
    std::this_thread::sleep_for(1s);
  }
  ~DaemonOnSmallDisk() {
    daemon->signal(SIGTERM);
    EXPECT_EQ(daemon->wait_exit(slowed(30s)), std::optional<int>(0)) << daemon->log();
  }
  VirtualRobotProcess rig;
  std::unique_ptr<ChildProcess> daemon;
  SmallDisk disk;
  bool answers;
};

TEST(FullDisk, AtTheCommitTheFitIsKeptAndCommittedOnceSpaceIsBack) {
  if (!tmpfs_mounts_allowed()) GTEST_SKIP() << "mount namespaces are not allowed here";
  // GIVEN the daemon with its state directory on a 2 MB tmpfs, 12 waypoints a run
  DaemonOnSmallDisk on;
  ASSERT_TRUE(on.answers) << on.daemon->log();
  const VirtualRobotProcess& rig = on.rig;
  const SmallDisk& disk = on.disk;

  // WHEN the disk fills while the run solves (after its last sample, before its commit)
  ASSERT_TRUE(rig.ask("start")["ok"].boolean());
  // (asked slowly until the last waypoint: the virtual robot shares the CPU)
  rig.wait_until_robot(
      [&] {
        const calibctl::JsonValue s = rig.ask("status");
        return s["waypoint"].integer() >= 12 || !s["running"].boolean();
      },
      slowed(240s));
  const calibctl::JsonValue solving = poll_until(
      rig,
      [](const calibctl::JsonValue& s) {
        const std::string state = s["state"].string();
        return state == "solve" || state == "validate" || state == "commit" || !s["running"].boolean();
      },
      slowed(240s));
  ASSERT_TRUE(solving["running"].boolean() && solving["state"].string() != "commit")
      << "the run passed its solve before the test saw it: " << solving["state"].string() << ": "
      << solving["reason"].string();
  // THEN the run fails, nothing is committed, the fit is kept in memory, no temp file is left
  const auto [end, stopped_s, reason] = fill_and_wait_for_end(rig, disk);
  EXPECT_TRUE(contains(reason, "the fit is kept in memory")) << reason;
  EXPECT_TRUE(end["pending_commit"].boolean());
  EXPECT_EQ(disk.bytes("calibration.toml"), "<absent>");
  EXPECT_TRUE(disk.temp_files().empty()) << disk.temp_files().front();
  std::printf("disk full at the commit (filled during %s): run %s %.2f s after the fill; calibration.toml %s\n"
              "reason: %s\n",
              solving["state"].string().c_str(), end["state"].string().c_str(), stopped_s,
              disk.bytes("calibration.toml") == "<absent>" ? "intact (none)" : "CHANGED", reason.c_str());
  // AND WHEN `calibctl commit` is asked on the full disk THEN it says why not
  int exit_code = 0;
  const std::string refused = calibctl_commit(rig, "commit-full", exit_code);
  EXPECT_EQ(exit_code, 1) << refused;
  EXPECT_TRUE(contains(refused, "commit of the fit kept in memory failed again")) << refused;
  EXPECT_TRUE(contains(refused, "No space left on device")) << refused;
  std::printf("calibctl commit on the full disk: %s", refused.c_str());
  // AND WHEN space is freed THEN `calibctl commit` commits the fit
  disk.free_space();
  const std::string committed = calibctl_commit(rig, "commit", exit_code);
  EXPECT_EQ(exit_code, 0) << committed;
  EXPECT_TRUE(contains(committed, "from memory")) << committed;
  std::printf("calibctl commit after freeing space: %s", committed.c_str());
  const calibctl::JsonValue after = rig.ask("status");
  EXPECT_EQ(after["state"].string(), "done");
  EXPECT_FALSE(after["pending_commit"].boolean());
  EXPECT_TRUE(rig.ask("show")["present"].boolean());
  const std::string calibration = disk.bytes("calibration.toml");
  ASSERT_NE(calibration, "<absent>");
}

TEST(FullDisk, AtWaypoint2And5TheRunStopsWithinOneWrite) {
  if (!tmpfs_mounts_allowed()) GTEST_SKIP() << "mount namespaces are not allowed here";
  // GIVEN the daemon with its state directory on a 2 MB tmpfs, 12 waypoints a run
  DaemonOnSmallDisk on;
  ASSERT_TRUE(on.answers) << on.daemon->log();
  const VirtualRobotProcess& rig = on.rig;
  const SmallDisk& disk = on.disk;

  // WHEN the disk fills at waypoint 2, and in the next run at waypoint 5
  // THEN each run stops within one write and the old calibration (none) stays
  fill_at_waypoint(rig, disk, 2, 1, "<absent>");
  fill_at_waypoint(rig, disk, 5, 2, "<absent>");
}

}  // namespace
}  // namespace cdpr::integration
