// Two real cdpr-calibd processes: the second on the same state directory
// exits non-zero naming the lock and the first one's pid, before it binds
// anything, and the first keeps its control socket and keeps answering; a
// second one on another state directory but the same socket path leaves the
// live socket alone too.

#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "../solver/model/test_robots.h"
#include "calibctl/control_client.h"
#include "daemon_process.h"
#include "src/formats/robot_toml.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

class DaemonFiles {
 public:
  DaemonFiles() {
    char pattern[] = "/tmp/cdpr-instance-XXXXXX";
    dir = mkdtemp(pattern);
    std::ofstream(dir + "/robot.toml") << formats::format_robot_toml(cdpr::test::large_robot());
  }
  ~DaemonFiles() { std::filesystem::remove_all(dir); }

  // A configuration with its own state directory and the given socket;
  // devices that are not there (the daemon retries them and starts anyway).
  std::string config(const std::string& name, const std::string& state_dir, const std::string& socket) const {
    const std::string path = dir + "/" + name + ".toml";
    std::ofstream(path) << "robot = \"" << dir << "/robot.toml\"\n[store]\nstate_dir = \"" << state_dir
                        << "\"\n[control]\nsocket = \"" << socket << "\"\n[winches]\nendpoint = \"unix:" << dir
                        << "/no-can.sock\"\n[load_cell]\nendpoint = \"tcp:127.0.0.1:1\"\n[pose]\nendpoint = \"unix:"
                        << dir << "/no-pose.sock\"\n[button]\nkind = \"none\"\n";
    return path;
  }

  std::string dir;
};

bool answers_status(const std::string& socket) {
  calibctl::ControlClient client;
  std::string error, response;
  return client.connect(socket, error) && client.request("status", response, error, 2000) &&
         response.find("\"ok\":true") != std::string::npos;
}

ino_t inode_of(const std::string& path) {
  struct stat info {};
  return stat(path.c_str(), &info) == 0 ? info.st_ino : 0;
}

TEST(SingleInstance, ASecondDaemonOnTheSameStateDirectoryExitsAndLeavesTheFirstAlone) {
  // GIVEN a running daemon, answering on its control socket
  DaemonFiles files;
  const std::string socket = files.dir + "/control";
  const std::string config = files.config("calibd", files.dir + "/state", socket);
  ChildProcess first({built_program("src/cdpr-calibd"), "--config", config}, files.dir + "/first.log");
  ASSERT_TRUE(wait_until([&] { return answers_status(socket); }, 20s)) << first.log();
  const ino_t socket_inode = inode_of(socket);

  // WHEN a second daemon starts with the same configuration
  ChildProcess second({built_program("src/cdpr-calibd"), "--config", config}, files.dir + "/second.log");
  const auto exit_status = second.wait_exit(20s);

  // THEN it exits 1, naming the lock file and the first daemon's pid
  ASSERT_TRUE(exit_status.has_value()) << "the second daemon is still running: " << second.log();
  EXPECT_EQ(*exit_status, 1);
  const std::string said = second.log();
  EXPECT_NE(said.find(files.dir + "/state/cdpr-calibd.lock"), std::string::npos) << said;
  EXPECT_NE(said.find("(pid " + std::to_string(first.pid()) + ")"), std::string::npos) << said;
  std::printf("second daemon said: %s", said.c_str());
  // AND the first keeps the same socket file and keeps answering
  EXPECT_EQ(inode_of(socket), socket_inode);
  EXPECT_TRUE(answers_status(socket)) << first.log();

  // AND WHEN the first is stopped THEN it exits 0 and removes its socket
  first.signal(SIGTERM);
  EXPECT_EQ(first.wait_exit(20s), std::optional<int>(0)) << first.log();
  EXPECT_FALSE(std::filesystem::exists(socket));
}

TEST(SingleInstance, ADaemonOnAnotherStateDirectoryButTheSameSocketLeavesTheLiveSocketAlone) {
  // GIVEN a running daemon
  DaemonFiles files;
  const std::string socket = files.dir + "/control";
  ChildProcess first({built_program("src/cdpr-calibd"), "--config", files.config("a", files.dir + "/a", socket)},
                     files.dir + "/first.log");
  ASSERT_TRUE(wait_until([&] { return answers_status(socket); }, 20s)) << first.log();
  const ino_t socket_inode = inode_of(socket);
  // WHEN another daemon with its own state directory is given the same socket path
  ChildProcess second({built_program("src/cdpr-calibd"), "--config", files.config("b", files.dir + "/b", socket)},
                      files.dir + "/second.log");
  const auto exit_status = second.wait_exit(20s);
  // THEN it exits 1 saying somebody listens there, and the first's socket is untouched and answering
  ASSERT_TRUE(exit_status.has_value()) << second.log();
  EXPECT_EQ(*exit_status, 1);
  EXPECT_NE(second.log().find("another process is listening"), std::string::npos) << second.log();
  EXPECT_EQ(inode_of(socket), socket_inode);
  EXPECT_TRUE(answers_status(socket)) << first.log();
}

}  // namespace
}  // namespace cdpr::integration
