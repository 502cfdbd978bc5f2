// The control socket server against a stub handler, through real Unix
// sockets: ordering, many concurrent clients, bounds, permissions, cleanup.

#include <grp.h>
#include <sys/inotify.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "src/daemon/control_server.h"
#include "test_groups.h"

namespace cdpr::daemon {
namespace {

class TempDir {
 public:
  TempDir() {
    char pattern[] = "/tmp/cdpr-control-XXXXXX";
    path_ = mkdtemp(pattern);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

// Answers "echo <n>" with "<n>" and counts requests.
struct StubHandler {
  int calls = 0;
  std::string operator()(std::string_view line) {
    ++calls;
    return "{\"echo\":\"" + std::string(line) + "\"}\n";
  }
};

int connect_to(const std::string& path) {
  const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path.c_str());
  if (connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

void send_text(int fd, const std::string& text) {
  ASSERT_EQ(send(fd, text.data(), text.size(), MSG_NOSIGNAL), static_cast<ssize_t>(text.size()));
}

// Runs the server's part of the event loop for `rounds` polls of 5 ms.
void pump(ControlServer& server, int rounds = 20) {
  for (int round = 0; round < rounds; ++round) {
    std::vector<pollfd> fds;
    server.append_poll_fds(fds);
    poll(fds.data(), fds.size(), 5);
    server.service(fds);
  }
}

// Reads what has arrived on a client socket (non-blocking).
std::string drain(int fd) {
  std::string text;
  char buffer[4096];
  for (;;) {
    const ssize_t got = recv(fd, buffer, sizeof(buffer), MSG_DONTWAIT);
    if (got <= 0) return text;
    text.append(buffer, static_cast<std::size_t>(got));
  }
}

TEST(ControlServer, TheSocketAppearsAtItsPathOnlyWhenItAcceptsConnections) {
  // GIVEN a watch on the socket's directory
  TempDir dir;
  const std::string directory = std::filesystem::path(dir / "control").parent_path();
  const int watch = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  ASSERT_GE(watch, 0);
  ASSERT_GE(inotify_add_watch(watch, directory.c_str(), IN_CREATE | IN_MOVED_TO), 0);
  // WHEN the server listens
  StubHandler handler;
  auto server = ControlServer::listen(dir / "control", std::ref(handler));
  ASSERT_TRUE(server.ok()) << server.status().message();
  // THEN "control" was never created in place (bound there, it would refuse
  // connections until listen(): a client that saw the file too early got
  // ECONNREFUSED); it was moved there, listening, and nothing else is left
  std::vector<char> events(4096);
  const ssize_t size = read(watch, events.data(), events.size());
  close(watch);
  ASSERT_GT(size, 0);
  bool created_in_place = false, moved_in = false;
  for (ssize_t at = 0; at < size;) {
    const auto* event = reinterpret_cast<const inotify_event*>(events.data() + at);
    const std::string name = event->len ? event->name : "";
    if (name == "control" && (event->mask & IN_CREATE)) created_in_place = true;
    if (name == "control" && (event->mask & IN_MOVED_TO)) moved_in = true;
    at += static_cast<ssize_t>(sizeof(inotify_event) + event->len);
  }
  EXPECT_FALSE(created_in_place);
  EXPECT_TRUE(moved_in);
  EXPECT_FALSE(std::filesystem::exists(dir / (std::string("control") + ControlServer::kStagingSuffix)));
  const int client = connect_to(dir / "control");
  EXPECT_GE(client, 0);
  if (client >= 0) close(client);
}

TEST(ControlServer, AnswersPipelinedRequestsInOrderOneLineEach) {
  // GIVEN a server with a stub handler and one connected client
  TempDir dir;
  StubHandler handler;
  auto server = ControlServer::listen(dir / "control", std::ref(handler));
  ASSERT_TRUE(server.ok()) << server.status().to_string();
  const int client = connect_to(dir / "control");
  ASSERT_GE(client, 0);
  // WHEN it sends three requests in one write, the last split over two writes
  send_text(client, "status\nshow\nhis");
  pump(*server.value());
  send_text(client, "tory\r\n");
  pump(*server.value());
  // THEN it gets three responses, in request order
  EXPECT_EQ(drain(client), "{\"echo\":\"status\"}\n{\"echo\":\"show\"}\n{\"echo\":\"history\r\"}\n");
  EXPECT_EQ(handler.calls, 3);
  close(client);
}

// A client that pipelines 2000 requests whose answers are 2 KiB each (a
// status with every CANopen node's state) and reads them only later: 4 MiB
// of answers, four times the pending-output bound. The server stops reading
// its requests while its answers wait, so it is answered in full instead
// of dropped as a client that never reads.
TEST(ControlServer, APipeliningClientWithLongAnswersIsAnsweredInFull) {
  // GIVEN a server whose answers are 2 KiB lines and a connected client
  TempDir dir;
  int calls = 0;
  const auto long_answers = [&calls](std::string_view) {
    ++calls;
    return std::string(2047, 'a') + "\n";
  };
  auto server = ControlServer::listen(dir / "control", long_answers);
  ASSERT_TRUE(server.ok()) << server.status().to_string();
  const int client = connect_to(dir / "control");
  ASSERT_GE(client, 0);
  // WHEN it sends 2000 requests in one write and reads nothing while the server runs
  std::string requests;
  for (int n = 0; n < 2000; ++n) requests += "status\n";
  send_text(client, requests);
  pump(*server.value(), 40);
  EXPECT_LT(calls, 2000) << "the server read every request while the answers piled up";
  // THEN, reading at its own pace, it gets every answer
  std::size_t lines = 0;
  for (int round = 0; round < 4000 && lines < 2000; ++round) {
    const std::string got = drain(client);
    lines += static_cast<std::size_t>(std::count(got.begin(), got.end(), '\n'));
    pump(*server.value(), 1);
  }
  EXPECT_EQ(lines, 2000u);
  EXPECT_EQ(calls, 2000);
  close(client);
}

TEST(ControlServer, ServesManyConcurrentClientsEachItsOwnAnswers) {
  // GIVEN 20 clients connected at the same time
  TempDir dir;
  StubHandler handler;
  auto server = ControlServer::listen(dir / "control", std::ref(handler));
  ASSERT_TRUE(server.ok());
  std::vector<int> clients;
  for (int k = 0; k < 20; ++k) {
    clients.push_back(connect_to(dir / "control"));
    pump(*server.value(), 1);  // the listen backlog is short: accept as they come
  }
  // WHEN each sends two requests naming itself, interleaved with the others
  for (int k = 0; k < 20; ++k) send_text(clients[k], "first " + std::to_string(k) + "\n");
  pump(*server.value());
  for (int k = 19; k >= 0; --k) send_text(clients[k], "second " + std::to_string(k) + "\n");
  pump(*server.value());
  // THEN each client gets exactly its own two answers, in order
  EXPECT_EQ(server.value()->client_count(), 20u);
  for (int k = 0; k < 20; ++k) {
    EXPECT_EQ(drain(clients[k]), "{\"echo\":\"first " + std::to_string(k) + "\"}\n{\"echo\":\"second " +
                                     std::to_string(k) + "\"}\n");
    close(clients[k]);
  }
  // AND closed clients are forgotten
  pump(*server.value());
  EXPECT_EQ(server.value()->client_count(), 0u);
}

TEST(ControlServer, AnswersARequestSentJustBeforeTheClientHalfCloses) {
  // GIVEN a client that sends one request and shuts down its sending side
  TempDir dir;
  StubHandler handler;
  auto server = ControlServer::listen(dir / "control", std::ref(handler));
  ASSERT_TRUE(server.ok());
  const int client = connect_to(dir / "control");
  send_text(client, "status\n");
  shutdown(client, SHUT_WR);
  // WHEN the server runs
  pump(*server.value());
  // THEN the answer still arrives and the connection is then closed
  EXPECT_EQ(drain(client), "{\"echo\":\"status\"}\n");
  EXPECT_EQ(server.value()->client_count(), 0u);
  close(client);
}

TEST(ControlServer, RefusesAnOverlongRequestAndKeepsServingTheClient) {
  // GIVEN a connected client
  TempDir dir;
  StubHandler handler;
  auto server = ControlServer::listen(dir / "control", std::ref(handler));
  ASSERT_TRUE(server.ok());
  const int client = connect_to(dir / "control");
  // WHEN it sends 10 kB without a newline, then a newline and a good request
  send_text(client, std::string(10'000, 'x'));
  pump(*server.value());
  send_text(client, "\nstatus\n");
  pump(*server.value());
  // THEN it gets one error line for the long request, then the answer; the handler never saw the long line
  const std::string answer = drain(client);
  EXPECT_NE(answer.find("\"ok\":false"), std::string::npos) << answer;
  EXPECT_NE(answer.find("longer than"), std::string::npos) << answer;
  EXPECT_NE(answer.find("{\"echo\":\"status\"}\n"), std::string::npos) << answer;
  EXPECT_EQ(handler.calls, 1);
  close(client);
}

TEST(ControlServer, WhenFullANewClientDisplacesTheStalestWithAReason) {
  // GIVEN the server full of clients, all of which asked something except the
  // first, which only connected (an idle or slow-loris connection)
  TempDir dir;
  StubHandler handler;
  auto server = ControlServer::listen(dir / "control", std::ref(handler));
  ASSERT_TRUE(server.ok());
  std::vector<int> clients;
  for (std::size_t k = 0; k < ControlServer::kMaxClients; ++k) {
    clients.push_back(connect_to(dir / "control"));
    if (k > 0) send_text(clients.back(), "stat");  // slow: the rest of the line comes later
    pump(*server.value(), 1);
  }
  for (std::size_t k = 1; k < clients.size(); ++k) send_text(clients[k], "us\n");
  pump(*server.value(), 3);
  // WHEN one more connects and asks
  const int extra = connect_to(dir / "control");
  send_text(extra, "status\n");
  pump(*server.value());
  // THEN it is answered, the idle first client is told why and closed, the others stay
  EXPECT_EQ(drain(extra), "{\"echo\":\"status\"}\n");
  EXPECT_NE(drain(clients[0]).find("too many control clients"), std::string::npos);
  EXPECT_EQ(server.value()->client_count(), ControlServer::kMaxClients);
  EXPECT_EQ(server.value()->counters().displaced, 1u);
  send_text(clients[1], "status\n");
  pump(*server.value());
  EXPECT_NE(drain(clients[1]).find("{\"echo\":\"status\"}\n"), std::string::npos);
  close(extra);
  for (const int fd : clients) close(fd);
}

TEST(ControlServer, OneServiceCallAnswersABoundedNumberOfRequests) {
  // GIVEN 8 clients that each pipelined hundreds of requests at once
  TempDir dir;
  StubHandler handler;
  auto server = ControlServer::listen(dir / "control", std::ref(handler));
  ASSERT_TRUE(server.ok());
  std::string flood;
  while (flood.size() + 2 <= ControlServer::kReadChunkBytes) flood += "s\n";
  std::vector<int> clients;
  for (int k = 0; k < 8; ++k) clients.push_back(connect_to(dir / "control"));
  pump(*server.value(), 2);
  ASSERT_EQ(server.value()->client_count(), 8u);
  for (const int fd : clients) send_text(fd, flood);
  // WHEN the loop serves them once
  std::vector<pollfd> fds;
  server.value()->append_poll_fds(fds);
  ASSERT_GT(poll(fds.data(), fds.size(), 1000), 0);
  const int before = handler.calls;
  server.value()->service(fds);
  // THEN at most the budget plus one client's chunk was answered in that call
  const int one_chunk = static_cast<int>(flood.size() / 2);
  EXPECT_LE(handler.calls - before, static_cast<int>(ControlServer::kMaxRequestsPerService) + one_chunk);
  // AND later calls answer everything, each client all of its requests
  pump(*server.value(), 40);
  EXPECT_EQ(handler.calls - before, 8 * one_chunk);
  for (const int fd : clients) close(fd);
}

TEST(ControlServer, SocketHasMode0660AndIsRemovedOnDestruction) {
  // GIVEN a server
  TempDir dir;
  StubHandler handler;
  const std::string path = dir / "control";
  {
    auto server = ControlServer::listen(path, std::ref(handler));
    ASSERT_TRUE(server.ok());
    // THEN its socket is group-accessible only
    struct stat info {};
    ASSERT_EQ(stat(path.c_str(), &info), 0);
    EXPECT_TRUE(S_ISSOCK(info.st_mode));
    EXPECT_EQ(info.st_mode & 0777, 0660u);
  }
  // WHEN it is destroyed THEN the path is gone
  EXPECT_FALSE(std::filesystem::exists(path));
}

// In a child: drops to user nobody with only group `gid`, connects, and
// exits 0 when the outcome is `expect_connected` (else 1; 2 if it could not drop).
int connect_as_nobody(const std::string& path, gid_t gid, bool expect_connected) {
  const pid_t child = fork();
  if (child == 0) {
    if (setgroups(0, nullptr) != 0 || setgid(gid) != 0 || setuid(65534) != 0) _exit(2);
    const int fd = connect_to(path);
    const bool denied = fd < 0 && errno == EACCES;
    _exit((expect_connected ? fd >= 0 : denied) ? 0 : 1);
  }
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 3;
}

TEST(ControlServer, SocketBelongsToTheConfiguredGroupAndOnlyItsMembersConnect) {
  // GIVEN a server whose socket is given to a group by its id (as root: any
  // existing group but our own; otherwise the test's own group, the only one
  // it may give)
  TempDir dir;
  StubHandler handler;
  const std::string path = dir / "control";
  const bool root = geteuid() == 0;
  const gid_t operators = root ? another_group().value_or(getegid()) : getegid();
  auto server = ControlServer::listen(path, std::ref(handler), 0660, std::to_string(operators));
  ASSERT_TRUE(server.ok()) << server.status().to_string();
  // THEN the socket is that group's, mode 0660
  struct stat info {};
  ASSERT_EQ(stat(path.c_str(), &info), 0);
  EXPECT_EQ(info.st_gid, operators);
  EXPECT_EQ(info.st_mode & 0777, 0660u);
  // AND an unknown group name is refused with its name
  auto unknown = ControlServer::listen(dir / "other", std::ref(handler), 0660, "no-such-group-cdpr");
  ASSERT_FALSE(unknown.ok());
  EXPECT_EQ(unknown.status().code(), hal::ErrorCode::kInvalidArgument);
  EXPECT_NE(unknown.status().message().find("no-such-group-cdpr"), std::string::npos);
  // AND so is a numeric id no group has (a typo would open the socket to
  // whoever is given that id later)
  const std::string unused = std::to_string(unused_group_id());
  auto unused_id = ControlServer::listen(dir / "third", std::ref(handler), 0660, unused);
  ASSERT_FALSE(unused_id.ok());
  EXPECT_NE(unused_id.status().message().find("'" + unused + "' does not exist"), std::string::npos)
      << unused_id.status().to_string();
  if (!root) GTEST_SKIP() << "connecting as other users needs root";
  // WHEN an unprivileged user in that group, and one outside it, connect
  ASSERT_EQ(chmod(std::filesystem::path(path).parent_path().c_str(), 0755), 0);
  // THEN the member gets in and the outsider is refused by the kernel
  EXPECT_EQ(connect_as_nobody(path, operators, true), 0);
  EXPECT_EQ(connect_as_nobody(path, operators + 1, false), 0);
}

TEST(ControlServer, ReplacesAStaleSocketButNeverAnotherFile) {
  // GIVEN a socket file left by a crashed daemon, and a regular file elsewhere
  TempDir dir;
  StubHandler handler;
  {
    const int stale = socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", (dir / "stale").c_str());
    ASSERT_EQ(bind(stale, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
    close(stale);
  }
  std::ofstream(dir / "precious") << "keep me";
  // WHEN servers are started on both paths
  auto on_stale = ControlServer::listen(dir / "stale", std::ref(handler));
  auto on_file = ControlServer::listen(dir / "precious", std::ref(handler));
  // THEN the stale socket is replaced and the regular file refused and kept
  EXPECT_TRUE(on_stale.ok()) << on_stale.status().to_string();
  ASSERT_FALSE(on_file.ok());
  EXPECT_EQ(on_file.status().code(), hal::ErrorCode::kInvalidArgument);
  std::ifstream kept(dir / "precious");
  std::string text;
  std::getline(kept, text);
  EXPECT_EQ(text, "keep me");
}

}  // namespace
}  // namespace cdpr::daemon
