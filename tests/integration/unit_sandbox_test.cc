// cdpr-calibd, the built program, inside the sandbox that
// systemd/cdpr-calibd.service states, calibrating the virtual robot; without
// systemd as PID 1, each of the unit's settings by the mechanism systemd uses:
//   SystemCallFilter=, SystemCallErrorNumber=EPERM, SystemCallArchitectures=,
//   RestrictAddressFamilies=, NoNewPrivileges=: seccomp filters resolved
//     from the unit file at build time (tests/sandbox: unit-sandbox-exec)
//   PrivateUsers=: a user namespace mapping only the service user and group
//     (bwrap --unshare-user --uid --gid; every other id shows as nobody)
//   User=/Group=: that user and group, in /etc/passwd and /etc/group as
//     sysusers makes them
//   ProtectSystem=strict, StateDirectory=, RuntimeDirectory=: / read-only
//     but the state and runtime directories (bwrap --ro-bind / / --bind)
//   PrivateTmp=: an empty /tmp of its own (--tmpfs /tmp), the build
//     directory bound back in (read-only) should it be under /tmp
//   CapabilityBoundingSet=, AmbientCapabilities=: none (--cap-drop ALL)
//   PrivateIPC=, ProtectHostname=: --unshare-ipc, --unshare-uts
//   UMask=0027
// The network stays shared: the virtual robot's Modbus TCP port is on the
// host's loopback, as a load cell would be on the robot's network.

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "src/formats/calibration_toml.h"
#include "../read_text.h"
#include "slowdown.h"
#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

constexpr int kServiceId = 4242;    // the unit's User= and Group=, cdpr-calib
constexpr int kOperatorsId = 4343;  // a group the unit does not run as

using cdpr::test::read_text;

// Why the kernel cannot give the sandbox (empty: it can). A missing
// bubblewrap is not a reason: `make deps` installs it.
std::string kernel_lacks_sandbox() {
  if (access("/proc/sys/kernel/seccomp/actions_avail", R_OK) != 0) {
    return "this kernel has no seccomp filters (CONFIG_SECCOMP_FILTER)";
  }
  if (access("/proc/self/ns/user", F_OK) != 0) return "this kernel has no user namespaces (CONFIG_USER_NS)";
  if (read_text("/proc/sys/user/max_user_namespaces").rfind("0", 0) == 0) {
    return "user namespaces are disabled (/proc/sys/user/max_user_namespaces is 0)";
  }
  if (geteuid() != 0 && read_text("/proc/sys/kernel/unprivileged_userns_clone").rfind("0", 0) == 0) {
    return "unprivileged user namespaces are disabled (kernel.unprivileged_userns_clone = 0); run as root";
  }
  if (geteuid() != 0 && read_text("/proc/sys/kernel/apparmor_restrict_unprivileged_userns").rfind("1", 0) == 0) {
    return "AppArmor restricts unprivileged user namespaces; run as root";
  }
  return "";
}

// The test's environment, but for the sanitizer build: LeakSanitizer's
// check at exit needs ptrace(), which the unit's filter refuses as it should
// (leaks are the in-process tests' to find).
std::vector<std::string> sandbox_environment() {
  std::vector<std::string> environment;
  std::string asan_options = "ASAN_OPTIONS=";
  for (char** variable = environ; *variable != nullptr; ++variable) {
    const std::string text = *variable;
    if (text.rfind(asan_options, 0) == 0) {
      asan_options = text + ":";
    } else {
      environment.push_back(text);
    }
  }
  environment.push_back(asan_options + "detect_leaks=0");
  return environment;
}

// cdpr-calibd started in the unit's sandbox with `config_path`; its output
// goes to `log_path`.
class SandboxedDaemon {
 public:
  SandboxedDaemon(const std::string& dir, const std::string& config_path, const std::string& log_path) {
    int info[2];
    EXPECT_EQ(pipe2(info, O_CLOEXEC), 0);
    const std::string id = std::to_string(kServiceId);
    std::vector<std::string> args = {
        "bwrap", "--unshare-user", "--uid", id, "--gid", id, "--unshare-ipc", "--unshare-uts",
        "--cap-drop", "ALL", "--die-with-parent", "--ro-bind", "/", "/", "--tmpfs", "/tmp",
        // The programs, where an installation would have them outside /tmp.
        "--ro-bind", CDPR_BINARY_DIR, CDPR_BINARY_DIR,
        "--ro-bind", dir, dir, "--bind", dir + "/state", dir + "/state", "--bind", dir + "/run", dir + "/run",
        "--ro-bind", dir + "/passwd", "/etc/passwd", "--ro-bind", dir + "/group", "/etc/group",
        "--info-fd", std::to_string(info[1]), "--",
        CDPR_BINARY_DIR "/tests/sandbox/unit-sandbox-exec", CDPR_BINARY_DIR "/tests/sandbox/cdpr-calibd.sandbox",
        CDPR_BINARY_DIR "/src/cdpr-calibd", "--config", config_path, "--sim-clock", dir + "/robot/clock"};
    std::vector<char*> argv;  // made before fork(): the child of a threaded process must not allocate
    for (std::string& arg : args) argv.push_back(arg.data());
    argv.push_back(nullptr);
    std::vector<std::string> environment = sandbox_environment();
    std::vector<char*> envp;
    for (std::string& variable : environment) envp.push_back(variable.data());
    envp.push_back(nullptr);
    bwrap_pid_ = fork();
    if (bwrap_pid_ == 0) {
      const int log = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (log < 0 || dup2(log, STDOUT_FILENO) < 0 || dup2(log, STDERR_FILENO) < 0) _exit(126);
      fcntl(info[1], F_SETFD, 0);  // bwrap writes the daemon's pid to it
      umask(0027);                 // UMask=
      execvpe(argv[0], argv.data(), envp.data());
      static const char kNoBwrap[] = "cannot run bwrap: make deps installs bubblewrap\n";
      [[maybe_unused]] const ssize_t ignored = write(STDERR_FILENO, kNoBwrap, sizeof(kNoBwrap) - 1);
      _exit(127);
    }
    close(info[1]);
    // {"child-pid": N} once the sandbox is set up; nothing if bwrap failed.
    std::string text;
    char buffer[256];
    for (ssize_t got; (got = read(info[0], buffer, sizeof(buffer))) > 0;) text.append(buffer, static_cast<std::size_t>(got));
    close(info[0]);
    if (const auto colon = text.find(':'); colon != std::string::npos) daemon_pid_ = std::atoi(text.c_str() + colon + 1);
  }

  ~SandboxedDaemon() {
    if (bwrap_pid_ > 0 && !exit_status_) {
      kill(bwrap_pid_, SIGKILL);  // --die-with-parent: the daemon follows
      waitpid(bwrap_pid_, nullptr, 0);
    }
  }

  // Whether `socket` appeared within `timeout` while the daemon ran.
  bool wait_for_socket(const std::string& socket, std::chrono::seconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      struct stat info {};
      if (stat(socket.c_str(), &info) == 0 && S_ISSOCK(info.st_mode)) return true;
      if (exited()) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }

  // SIGTERM to the daemon (as systemctl stop); its exit status.
  int stop() {
    if (!exited() && daemon_pid_ > 0) kill(daemon_pid_, SIGTERM);
    return wait_exit();
  }

  int wait_exit() {
    if (!exit_status_) {
      int status = 0;
      waitpid(bwrap_pid_, &status, 0);
      exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    return *exit_status_;
  }

 private:
  bool exited() {
    if (exit_status_) return true;
    int status = 0;
    if (waitpid(bwrap_pid_, &status, WNOHANG) != bwrap_pid_) return false;
    exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return true;
  }

  pid_t bwrap_pid_ = -1;
  pid_t daemon_pid_ = -1;
  std::optional<int> exit_status_;
};

// The virtual robot on a thread, and what the sandboxed daemon sees: its
// configuration, state and runtime directories, the unit's user and group.
class SandboxRig {
 public:
  explicit SandboxRig(const std::string& control_group = "") {
    char pattern[] = "/tmp/cdpr-sandbox-XXXXXX";
    dir = mkdtemp(pattern);
    virtual_robot::VirtualRobotOptions options = large_robot_acceptance_options();
    options.dir = dir + "/robot";
    for (const char* sub : {"/robot", "/state", "/run"}) std::filesystem::create_directories(dir + sub);
    auto created = virtual_robot::VirtualRobot::create(options);
    if (!created) ADD_FAILURE() << created.error();
    robot = std::move(*created);
    robot_thread = std::thread([this] { robot->run(stop_robot); });

    socket = dir + "/run/control";
    std::ofstream(dir + "/passwd") << "root:x:0:0:root:/root:/bin/sh\n"
                                   << "cdpr-calib:x:" << kServiceId << ":" << kServiceId
                                   << "::/var/lib/cdpr-calib:/usr/sbin/nologin\n";
    std::ofstream(dir + "/group") << "root:x:0:\ncdpr-calib:x:" << kServiceId << ":\nrobot-operators:x:"
                                  << kOperatorsId << ":cdpr-calib\n";
    // The settings of make demo (tools/demo.sh) and of the in-process rig
    // (fast_daemon_config): physics 20x real time, a loaded test machine
    // (both stretched in the sanitizer build: slowdown.h).
    std::ofstream config(config_path());
    config << "robot = \"" << dir << "/robot/robot.toml\"\n" << kLoadedMachineUnsafeOk
           << "[store]\nstate_dir = \"" << dir << "/state\"\n"
           << "[control]\nsocket = \"" << socket << "\"\n";
    if (!control_group.empty()) config << "group = \"" << control_group << "\"\n";
    config << "[winches]\nendpoint = \"" << robot->can_endpoint()
           << "\"\nheartbeat_timeout_ms = " << 3000 * slowdown() << "\n"
           << "[winches.drive]\nconsumer_heartbeat_ms = " << 500 * slowdown() << "\n"
           << "[load_cell]\nendpoint = \"" << robot->modbus_endpoint() << "\"\nfault_timeout_ms = "
           << 1000 * slowdown() << "\n"
           << "[pose]\nendpoint = \"" << robot->pose_endpoint() << "\"\n"
           << "[button]\nkind = \"none\"\n"
           << "[limits]\nsettle_timeout_s = " << 15 * slowdown() << ".0\npose_stale_ms = " << 3000 * slowdown() << "\n";
  }

  ~SandboxRig() {
    stop_robot.store(true);
    robot_thread.join();
    if (!keep_dir) std::filesystem::remove_all(dir);
  }

  std::string config_path() const { return dir + "/cdpr-calibd.toml"; }
  std::string log_path() const { return dir + "/daemon.log"; }
  std::string log() const { return read_text(log_path()); }

  std::string dir;
  std::string socket;
  bool keep_dir = false;
  std::unique_ptr<virtual_robot::VirtualRobot> robot;
  std::atomic<bool> stop_robot{false};
  std::thread robot_thread;
};

#define SKIP_WITHOUT_KERNEL_SANDBOX()                                                     \
  if (const std::string lacking = kernel_lacks_sandbox(); !lacking.empty()) {             \
    GTEST_SKIP() << "cannot reproduce the unit's sandbox: " << lacking;                   \
  }

TEST(UnitSandbox, FullCalibrationOfTheVirtualRobotWithTheDaemonInsideTheUnitsSandbox) {
  SKIP_WITHOUT_KERNEL_SANDBOX();
  // GIVEN the virtual large robot and cdpr-calibd in the unit's sandbox, the example's [control] (no group)
  SandboxRig rig;
  SandboxedDaemon daemon(rig.dir, rig.config_path(), rig.log_path());
  ASSERT_TRUE(daemon.wait_for_socket(rig.socket, slowed(std::chrono::seconds(30))))
      << "the sandboxed daemon did not open its control socket; its log:\n" << rig.log();

  // WHEN the operator starts a calibration (once the nodes' heartbeats are in) and it runs to its end
  std::this_thread::sleep_for(std::chrono::seconds(1));
  ASSERT_TRUE(ask_daemon(rig.socket, "start")["ok"].boolean()) << rig.log();
  const RobotDeadline deadline(rig.robot->clock(), slowed(std::chrono::minutes(5)));
  calibctl::JsonValue status;
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    status = ask_daemon(rig.socket, "status");
  } while (status["running"].boolean() && !deadline.passed());
  rig.keep_dir = true;  // for diagnosis, unless everything below passes

  // THEN it committed a calibration from 35 waypoints into its state directory
  ASSERT_EQ(status["state"].string(), "done") << status["reason"].string() << "; log:\n" << rig.log();
  EXPECT_EQ(status["samples"].integer(), 35);
  const auto calibration = formats::read_calibration_toml(rig.dir + "/state/calibration.toml");
  ASSERT_TRUE(calibration) << calibration.error().message();
  // AND every anchor is within 0.10 m of the truth
  for (int i = 0; i < kCableCount; ++i) {
    const double error_m = (calibration->winches[i].anchor_world - rig.robot->truth().winches[i].anchor_world).norm();
    EXPECT_LT(error_m, 0.10) << "cable " << i;
  }
  // AND a SIGTERM stops it cleanly (exit 0: no restart under Restart=on-failure)
  EXPECT_EQ(daemon.stop(), 0) << rig.log();
  rig.keep_dir = ::testing::Test::HasFailure();
}

TEST(UnitSandbox, AControlGroupThatIsTheUnitsGroupNeedsNoChown) {
  SKIP_WITHOUT_KERNEL_SANDBOX();
  // GIVEN [control] group naming the unit's Group= (the recipe for another group: Group= in a drop-in)
  SandboxRig rig("cdpr-calib");
  // WHEN the daemon starts in the unit's sandbox
  SandboxedDaemon daemon(rig.dir, rig.config_path(), rig.log_path());
  // THEN its socket is there and answers (the socket took the group at bind, no chown was needed)
  ASSERT_TRUE(daemon.wait_for_socket(rig.socket, slowed(std::chrono::seconds(30)))) << rig.log();
  EXPECT_TRUE(ask_daemon(rig.socket, "status")["ok"].boolean());
  EXPECT_EQ(daemon.stop(), 0) << rig.log();
}

TEST(UnitSandbox, AControlGroupTheUnitDoesNotRunAsStopsTheDaemonWithTheRecipe) {
  SKIP_WITHOUT_KERNEL_SANDBOX();
  // GIVEN [control] group naming a group that is neither the unit's Group= nor mapped by PrivateUsers=
  SandboxRig rig("robot-operators");
  // WHEN the daemon starts in the unit's sandbox
  SandboxedDaemon daemon(rig.dir, rig.config_path(), rig.log_path());
  // THEN it exits 1 before opening the socket (systemd restarts it, the log says why) and names the fix
  EXPECT_EQ(daemon.wait_exit(), 1) << rig.log();
  EXPECT_NE(rig.log().find("Operation not permitted"), std::string::npos) << rig.log();
  EXPECT_NE(rig.log().find("Group=robot-operators"), std::string::npos) << rig.log();
  EXPECT_FALSE(std::filesystem::exists(rig.socket));
}

}  // namespace
}  // namespace cdpr::integration
