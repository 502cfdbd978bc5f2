// The real cdpr-calibd on a configuration whose robot file is missing, or
// whose state directory is a file: it exits 1 before it says ready, and its
// one line names the configuration file, the line and the key to fix (it
// once said only what the robot parser or the lock could not open).

#include <chrono>
#include <filesystem>
#include <fstream>

#include "../solver/model/test_robots.h"
#include "daemon_process.h"
#include "src/formats/robot_toml.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

class StartupFiles {
 public:
  StartupFiles() {
    char pattern[] = "/tmp/cdpr-startup-XXXXXX";
    dir = mkdtemp(pattern);
    std::ofstream(dir + "/robot.toml") << formats::format_robot_toml(cdpr::test::large_robot());
  }
  ~StartupFiles() { std::filesystem::remove_all(dir); }

  // robot on line 1, state_dir on line 3; devices that are not there.
  std::string config(const std::string& robot, const std::string& state_dir) const {
    const std::string path = dir + "/cdpr-calibd.toml";
    std::ofstream(path) << "robot = \"" << robot << "\"\n[store]\nstate_dir = \"" << state_dir
                        << "\"\n[control]\nsocket = \"" << dir << "/control\"\n[winches]\nendpoint = \"unix:" << dir
                        << "/no-can.sock\"\n[load_cell]\nendpoint = \"tcp:127.0.0.1:1\"\n[pose]\nendpoint = \"unix:"
                        << dir << "/no-pose.sock\"\n[button]\nkind = \"none\"\n";
    return path;
  }

  // The daemon's exit status and what it said.
  std::pair<std::optional<int>, std::string> run(const std::string& config_path) const {
    ChildProcess daemon({built_program("src/cdpr-calibd"), "--config", config_path}, dir + "/daemon.log");
    const auto status = daemon.wait_exit(20s);
    return {status, daemon.log()};
  }

  std::string dir;
};

TEST(StartupRefusal, AMissingRobotFileNamesTheConfigurationLineAndKey) {
  // GIVEN a configuration whose robot file does not exist
  StartupFiles files;
  const std::string config = files.config(files.dir + "/no-such-robot.toml", files.dir + "/state");
  // WHEN the daemon starts
  const auto [status, said] = files.run(config);
  // THEN it exits 1 naming file:line:key and the path, and never says ready
  ASSERT_TRUE(status.has_value()) << said;
  EXPECT_EQ(*status, 1) << said;
  EXPECT_NE(said.find(config + ":1: robot: cannot read \"" + files.dir + "/no-such-robot.toml\""), std::string::npos)
      << said;
  EXPECT_EQ(said.find("ready"), std::string::npos) << said;
}

TEST(StartupRefusal, AStateDirectoryThatIsAFileNamesTheConfigurationLineAndKey) {
  // GIVEN a configuration whose state directory is a regular file
  StartupFiles files;
  std::ofstream(files.dir + "/state-file") << "not a directory\n";
  const std::string config = files.config(files.dir + "/robot.toml", files.dir + "/state-file");
  // WHEN the daemon starts
  const auto [status, said] = files.run(config);
  // THEN it exits 1 naming file:line:key, and the file is left as it was
  ASSERT_TRUE(status.has_value()) << said;
  EXPECT_EQ(*status, 1) << said;
  EXPECT_NE(said.find(config + ":3: store.state_dir: \"" + files.dir + "/state-file\" is not a directory"),
            std::string::npos)
      << said;
  EXPECT_EQ(said.find("ready"), std::string::npos) << said;
  std::ifstream left(files.dir + "/state-file");
  std::string line;
  std::getline(left, line);
  EXPECT_EQ(line, "not a directory");
}

}  // namespace
}  // namespace cdpr::integration
