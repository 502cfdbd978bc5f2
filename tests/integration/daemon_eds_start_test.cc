// cdpr-calibd at start with the CANopen devices' EDS files: a configuration
// the device cannot take stops it (exit 1) naming node, file and what does
// not fit, before anything is opened; without EDS files it starts and says
// which nodes it configures with the CiA defaults.

#include <chrono>
#include <filesystem>
#include <fstream>

#include "../solver/model/test_robots.h"
#include "daemon_process.h"
#include "src/formats/robot_toml.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

// A daemon configuration in a fresh directory, devices absent, plus `extra` TOML.
std::string write_config(const std::string& dir, const std::string& extra) {
  std::ofstream(dir + "/robot.toml") << formats::format_robot_toml(cdpr::test::large_robot());
  const std::string path = dir + "/cdpr-calibd.toml";
  std::ofstream(path) << "robot = \"" << dir << "/robot.toml\"\n[store]\nstate_dir = \"" << dir
                      << "/state\"\n[control]\nsocket = \"" << dir << "/control\"\n[winches]\nendpoint = \"unix:" << dir
                      << "/no-can.sock\"\n" << extra << "[load_cell]\nendpoint = \"tcp:127.0.0.1:1\"\n[pose]\n"
                      << "endpoint = \"unix:" << dir << "/no-pose.sock\"\n[button]\nkind = \"none\"\n";
  return path;
}

struct TempDir {
  TempDir() {
    char pattern[] = "/tmp/cdpr-eds-start-XXXXXX";
    path = mkdtemp(pattern);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string path;
};

TEST(DaemonEdsStart, ADriveTheConfigurationDoesNotFitStopsTheStartNamingNodeAndFile) {
  // GIVEN the drives' EDS of a maxon EPOS4 (rpm) and no [winches.mechanics]
  TempDir dir;
  const std::string eds = std::string(CDPR_SOURCE_DIR) + "/systemd/eds/maxon-epos4.eds";
  const std::string config = write_config(dir.path, "[winches.drive]\neds = \"" + eds + "\"\n");
  // WHEN the daemon starts
  ChildProcess daemon({built_program("src/cdpr-calibd"), "--config", config}, dir.path + "/daemon.log");
  // THEN it exits 1 naming the configuration, the node and why
  const auto status = daemon.wait_exit(20s);
  ASSERT_TRUE(status.has_value()) << daemon.log();
  EXPECT_EQ(*status, 1);
  EXPECT_NE(daemon.log().find("configuration " + config + ": winches: node 1: 0x60A9 (SI unit velocity) = 0x00B44700 "
                              "(rpm): the drive counts motor revolutions; set [winches.mechanics]"),
            std::string::npos)
      << daemon.log();
}

TEST(DaemonEdsStart, WithoutEdsFilesItStartsAndSaysItUsesTheCiaDefaults) {
  // GIVEN no EDS configured
  TempDir dir;
  const std::string config = write_config(dir.path, "");
  // WHEN the daemon starts THEN it logs the nodes configured from the CiA defaults, and runs
  ChildProcess daemon({built_program("src/cdpr-calibd"), "--config", config}, dir.path + "/daemon.log");
  const auto deadline = std::chrono::steady_clock::now() + 20s;
  while (daemon.log().find("ready:") == std::string::npos && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(50ms);
  }
  EXPECT_NE(daemon.log().find("winches: no EDS for drives 1, 2, 3, 4; encoders 11, 12, 13, 14"), std::string::npos)
      << daemon.log();
  EXPECT_TRUE(daemon.running()) << daemon.log();
  daemon.signal(SIGTERM);
  EXPECT_EQ(daemon.wait_exit(20s), std::optional<int>(0)) << daemon.log();
}

}  // namespace
}  // namespace cdpr::integration
