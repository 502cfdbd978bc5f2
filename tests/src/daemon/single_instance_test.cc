// One daemon per state directory and per control socket, inside one
// process (flock conflicts between two open file descriptions as between
// two processes; tests/integration/single_instance_test.cc runs two real
// daemons): the second lock names the first holder, a live socket is never
// taken over, and a server removes only the socket file it bound.

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>
#include <string>

#include <gtest/gtest.h>

#include "../store/store_test_support.h"
#include "src/daemon/control_server.h"
#include "src/daemon/instance_lock.h"
#include "../../text_contains.h"

namespace cdpr::daemon {
namespace {

using store::test::TempStateDir;

using ::cdpr::test::contains;

std::string echo(std::string_view line) { return std::string(line) + "\n"; }

// One request through a fresh connection, with the server pumped meanwhile.
std::string ask(ControlServer& server, const std::string& request) {
  const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", server.path().c_str());
  if (connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return "<no connection>";
  }
  const std::string line = request + "\n";
  EXPECT_EQ(send(fd, line.data(), line.size(), MSG_NOSIGNAL), static_cast<ssize_t>(line.size()));
  std::string answer;
  for (int round = 0; round < 100 && answer.find('\n') == std::string::npos; ++round) {
    std::vector<pollfd> fds;
    server.append_poll_fds(fds);
    poll(fds.data(), fds.size(), 5);
    server.service(fds);
    char buffer[256];
    const ssize_t got = recv(fd, buffer, sizeof(buffer), MSG_DONTWAIT);
    if (got > 0) answer.append(buffer, static_cast<std::size_t>(got));
  }
  close(fd);
  return answer;
}

TEST(InstanceLock, ASecondLockOnTheStateDirectoryIsRefusedNamingTheFileAndThePid) {
  // GIVEN a state directory that does not exist yet, locked by a first instance
  TempStateDir dir;
  const std::string state_dir = dir.path() + "/state";
  auto first = InstanceLock::acquire(state_dir);
  ASSERT_TRUE(first.ok()) << first.status().to_string();
  // WHEN a second instance tries the same directory
  const auto second = InstanceLock::acquire(state_dir);
  // THEN it is refused, naming the lock file and the holder's pid
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), hal::ErrorCode::kInvalidState);
  EXPECT_TRUE(contains(second.status().message(), state_dir + "/cdpr-calibd.lock")) << second.status().to_string();
  EXPECT_TRUE(contains(second.status().message(), "(pid " + std::to_string(getpid()) + ")"))
      << second.status().to_string();
  // AND once the first lets go, the lock is free again
  first.value().reset();
  EXPECT_TRUE(InstanceLock::acquire(state_dir).ok());
}

TEST(InstanceLock, AStateDirectoryThatCannotBeMadeIsAnIoErrorNamingTheLock) {
  // GIVEN a file where the state directory's parent should be
  TempStateDir dir;
  std::ofstream(dir.path() + "/file") << "x";
  // WHEN locking a state directory below it
  const auto lock = InstanceLock::acquire(dir.path() + "/file/state");
  // THEN an i/o error names the lock file
  ASSERT_FALSE(lock.ok());
  EXPECT_EQ(lock.status().code(), hal::ErrorCode::kIoError);
  EXPECT_TRUE(contains(lock.status().message(), "file/state/cdpr-calibd.lock")) << lock.status().to_string();
}

TEST(ControlServerPath, ALiveSocketIsNeverTakenOverAndKeepsAnswering) {
  // GIVEN a server listening at a path
  TempStateDir dir;
  const std::string path = dir.path() + "/control";
  auto first = ControlServer::listen(path, echo);
  ASSERT_TRUE(first.ok()) << first.status().to_string();
  // WHEN a second server is asked to listen there
  const auto second = ControlServer::listen(path, echo);
  // THEN it is refused, and the first one still answers at the path
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.status().code(), hal::ErrorCode::kInvalidState);
  EXPECT_TRUE(contains(second.status().message(), "another process is listening")) << second.status().to_string();
  EXPECT_EQ(ask(*first.value(), "still here"), "still here\n");
}

TEST(ControlServerPath, AStaleSocketIsReplacedAndOnlyTheBoundFileIsRemoved) {
  // GIVEN a socket file nobody listens on (what a killed daemon leaves)
  TempStateDir dir;
  const std::string path = dir.path() + "/control";
  const int dead = socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path.c_str());
  ASSERT_EQ(bind(dead, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
  close(dead);
  ASSERT_TRUE(std::filesystem::is_socket(path));
  // WHEN a server listens there THEN it replaces the stale file
  auto server = ControlServer::listen(path, echo);
  ASSERT_TRUE(server.ok()) << server.status().to_string();
  EXPECT_EQ(ask(*server.value(), "replaced"), "replaced\n");
  // AND WHEN somebody else's socket takes the path while it runs, and the first server ends
  std::filesystem::rename(path, dir.path() + "/moved-away");
  auto other = ControlServer::listen(path, echo);
  ASSERT_TRUE(other.ok()) << other.status().to_string();
  server.value().reset();
  // THEN the other's socket is left in place, still answering
  EXPECT_TRUE(std::filesystem::is_socket(path));
  EXPECT_EQ(ask(*other.value(), "mine"), "mine\n");
  // AND the file the first server bound is removed under its own name only when it is still there
  EXPECT_TRUE(std::filesystem::exists(dir.path() + "/moved-away"));
}

}  // namespace
}  // namespace cdpr::daemon
