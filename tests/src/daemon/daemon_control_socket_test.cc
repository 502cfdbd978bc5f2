// cdpr-calibd.toml [control] socket and group, end to end through the
// daemon loop: the configured file becomes the daemon's control socket with
// the configured group and mode 0660, and a group that does not exist stops
// the start with its name. (control_server_test.cc checks that the kernel
// then lets only that group's members in.)

#include <grp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../store/store_test_support.h"
#include "daemon_on_fakes.h"
#include "config_text.h"
#include "test_groups.h"

namespace cdpr::daemon {
namespace {

using test::DaemonOnFakes;

// The state directory and control socket in `dir`; `control_lines` are
// added to [control].
DaemonConfig config_in(const std::string& dir, const std::string& control_lines) {
  const std::string text = "robot = \"" + dir + "/robot.toml\"\n[store]\nstate_dir = \"" + dir +
                           "\"\n[control]\nsocket = \"" + dir + "/control\"\n" + control_lines;
  auto config = parse_daemon_config(test::with_endpoints(text), "cdpr-calibd.toml");
  EXPECT_TRUE(config) << config.error().message();
  return config ? *config : DaemonConfig{};
}

TEST(DaemonControlSocket, GetsTheConfiguredGroupByNameAndMode0660) {
  const std::optional<gid_t> gid = another_group();
  if (!gid) GTEST_SKIP() << "no group to give the socket to besides our own (run as root)";
  const group* entry = getgrgid(*gid);
  ASSERT_NE(entry, nullptr);
  // GIVEN a configuration whose [control] group names a group other than the daemon's
  store::test::TempStateDir dir;
  const DaemonConfig config = config_in(dir.path(), "group = \"" + std::string(entry->gr_name) + "\"\n");
  // WHEN the daemon starts
  DaemonOnFakes daemon(config);
  const hal::Status started = daemon.start();
  ASSERT_TRUE(started.ok()) << started.to_string();
  // THEN its control socket is at the configured path, that group's, mode 0660
  struct stat info {};
  ASSERT_EQ(stat((dir.path() + "/control").c_str(), &info), 0);
  EXPECT_TRUE(S_ISSOCK(info.st_mode));
  EXPECT_EQ(info.st_gid, *gid);
  EXPECT_EQ(info.st_mode & 0777, 0660u);
}

TEST(DaemonControlSocket, WithoutAGroupKeepsTheDaemonsOwnGroup) {
  // GIVEN a configuration without [control] group
  store::test::TempStateDir dir;
  const DaemonConfig config = config_in(dir.path(), "");
  // WHEN the daemon starts
  DaemonOnFakes daemon(config);
  ASSERT_TRUE(daemon.start().ok());
  // THEN the socket has the daemon's group, mode 0660
  struct stat info {};
  ASSERT_EQ(stat((dir.path() + "/control").c_str(), &info), 0);
  EXPECT_EQ(info.st_gid, getegid());
  EXPECT_EQ(info.st_mode & 0777, 0660u);
}

TEST(DaemonControlSocket, AGroupThatDoesNotExistStopsTheStartNamingIt) {
  // GIVEN a configuration naming a group the system does not have
  store::test::TempStateDir dir;
  const DaemonConfig config = config_in(dir.path(), "group = \"no-such-group-cdpr\"\n");
  // WHEN the daemon starts
  DaemonOnFakes daemon(config);
  const hal::Status started = daemon.start();
  // THEN it refuses, naming the group, and leaves no socket behind
  ASSERT_FALSE(started.ok());
  EXPECT_NE(started.message().find("no-such-group-cdpr"), std::string::npos) << started.to_string();
  EXPECT_FALSE(std::filesystem::exists(dir.path() + "/control"));
}

}  // namespace
}  // namespace cdpr::daemon
