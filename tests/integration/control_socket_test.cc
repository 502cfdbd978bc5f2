// The daemon's control socket under concurrent clients, with the daemon
// running against the virtual robot: every request gets its own answer,
// simultaneous presses start exactly one run, and an abort stops it; under
// 100 polling clients plus malformed, oversized, slow-loris and flooding
// ones, status keeps being answered and the run keeps stepping.

#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <random>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

virtual_robot::VirtualRobotOptions small_robot_five_times_faster() {
  virtual_robot::VirtualRobotOptions options;
  options.preset = sim::Preset::kSmall;
  options.time_scale = 5.0;
  return options;
}

TEST(ControlSocket, ConcurrentClientsEachGetTheirAnswersAndStartOneRunOnly) {
  // GIVEN the daemon against the virtual small robot, its CANopen nodes up
  VirtualRobotRig rig(small_robot_five_times_faster());
  std::this_thread::sleep_for(std::chrono::seconds(1));

  // WHEN 8 clients poll status 25 times each while 4 others press start at the same moment
  std::mutex mutex;
  int status_answers = 0, started = 0, refused = 0;
  std::vector<std::string> problems;
  std::vector<std::thread> clients;
  for (int k = 0; k < 8; ++k) {
    clients.emplace_back([&] {
      calibctl::ControlClient client;
      std::string error, response;
      if (!client.connect(rig.config.control_socket, error)) {
        std::lock_guard lock(mutex);
        problems.push_back(error);
        return;
      }
      for (int n = 0; n < 25; ++n) {
        const bool answered = client.request("status", response, error);
        const auto value = calibctl::JsonValue::parse(response);
        std::lock_guard lock(mutex);
        if (answered && value && (*value)["ok"].boolean() && !(*value)["state"].string().empty()) {
          ++status_answers;
        } else {
          problems.push_back(answered ? response : error);
        }
      }
    });
  }
  for (int k = 0; k < 4; ++k) {
    clients.emplace_back([&] {
      const calibctl::JsonValue answer = rig.ask("start");
      std::lock_guard lock(mutex);
      (answer["ok"].boolean() ? started : refused)++;
    });
  }
  for (std::thread& client : clients) client.join();

  // THEN every status request was answered, and exactly one start began a run
  EXPECT_TRUE(problems.empty()) << problems.front();
  EXPECT_EQ(status_answers, 8 * 25);
  EXPECT_EQ(started, 1);
  EXPECT_EQ(refused, 3);
  EXPECT_TRUE(rig.ask("status")["running"].boolean());

  // AND WHEN the operator aborts THEN the run ends aborted with the abort as its reason
  EXPECT_TRUE(rig.ask("abort")["ok"].boolean());
  calibctl::JsonValue status = rig.ask("status");
  for (int n = 0; n < 50 && status["running"].boolean(); ++n) {  // the abort state stops the winches first
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    status = rig.ask("status");
  }
  EXPECT_FALSE(status["running"].boolean());
  EXPECT_EQ(status["state"].string(), "aborted");
  EXPECT_NE(status["reason"].string().find("abort"), std::string::npos) << status["reason"].string();
  EXPECT_FALSE(rig.ask("show")["present"].boolean());  // nothing committed
}

// A raw connection, for clients calibctl would never be: blocking, with a
// receive timeout so a stalled daemon fails the test instead of hanging it.
int raw_connect(const std::string& path) {
  const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::snprintf(address.sun_path, sizeof(address.sun_path), "%s", path.c_str());
  const timeval timeout{10, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof(timeout));
  if (connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

bool send_all(int fd, const std::string& bytes) {
  return send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(bytes.size());
}

// Reads until `lines` response lines arrived; false on timeout or close.
bool receive_lines(int fd, int lines, std::string& text) {
  char buffer[65536];
  while (std::count(text.begin(), text.end(), '\n') < lines) {
    const ssize_t got = recv(fd, buffer, sizeof(buffer), 0);
    if (got <= 0) return false;
    text.append(buffer, static_cast<std::size_t>(got));
  }
  return true;
}

TEST(ControlSocket, UnderLoadAndAbuseStatusIsServedAndTheRunKeepsStepping) {
  // GIVEN the daemon against the virtual small robot, its CANopen nodes up
  VirtualRobotRig rig(small_robot_five_times_faster());
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const std::string& path = rig.config.control_socket;

  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::vector<std::string> problems;
  const auto problem = [&](std::string what) {
    std::lock_guard lock(mutex);
    problems.push_back(std::move(what));
  };
  std::atomic<int> status_answers{0}, abuse_answers{0};
  std::vector<std::thread> threads;
  // WHEN 100 clients poll status every 20 ms (5000 requests/s in all),
  for (int k = 0; k < 100; ++k) {
    threads.emplace_back([&] {
      calibctl::ControlClient client;
      std::string error, response;
      if (!client.connect(path, error)) return problem(error);
      while (!stop.load()) {
        if (!client.request("status", response, error)) return problem("status: " + error);
        const auto value = calibctl::JsonValue::parse(response);
        if (!value || !(*value)["ok"].boolean()) return problem("status: " + response);
        ++status_answers;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
  }
  // AND 10 slow-loris clients trickle a request that never ends,
  for (int k = 0; k < 10; ++k) {
    threads.emplace_back([&] {
      const int fd = raw_connect(path);
      while (fd >= 0 && !stop.load() && send_all(fd, "s")) std::this_thread::sleep_for(std::chrono::milliseconds(50));
      if (fd >= 0) close(fd);
    });
  }
  // AND 5 send 64 KiB lines, 5 send binary garbage lines, 2 pipeline 2000 requests at once,
  for (int k = 0; k < 12; ++k) {
    threads.emplace_back([&, k] {
      std::mt19937 random(k);
      while (!stop.load()) {
        const int fd = raw_connect(path);
        if (fd < 0) return problem("abuser cannot connect");
        std::string request;
        int lines = 1;
        if (k < 5) {
          request = std::string(65536, 'x') + "\nstatus\n";
          lines = 2;
        } else if (k < 10) {
          for (int n = 0; n < 200; ++n) {
            const char byte = static_cast<char>(1 + random() % 255);
            request += byte == '\n' ? 'x' : byte;
          }
          request += "\n";
        } else {
          for (int n = 0; n < 2000; ++n) request += "status\n";
          lines = 2000;
        }
        std::string answer;
        if (!send_all(fd, request) || !receive_lines(fd, lines, answer)) {
          close(fd);
          return problem("abuser " + std::to_string(k) + " got no answer: " + answer.substr(0, 200));
        }
        if (k < 10 && answer.find("\"ok\":false") == std::string::npos) problem("abuse accepted: " + answer);
        abuse_answers += lines;
        close(fd);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
  }
  // AND an operator starts a calibration in the middle of it
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const calibctl::JsonValue started = rig.ask("start");
  EXPECT_TRUE(started["ok"].boolean()) << started["error"].string();

  // THEN the run keeps stepping: its state and waypoint keep changing while the load goes on
  std::set<std::pair<std::string, double>> seen;
  std::string last_state, last_reason;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(90);
  while (seen.size() < 4 && std::chrono::steady_clock::now() < deadline) {
    const calibctl::JsonValue status = rig.ask("status");
    seen.insert({status["state"].string(), status["progress"].number()});
    last_state = status["state"].string();
    last_reason = status["reason"].string();
    if (!status["running"].boolean()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const int answers_during_run = status_answers.load();
  stop.store(true);
  for (std::thread& thread : threads) thread.join();
  std::string states;
  for (const auto& [state, progress] : seen) states += " " + state + "@" + std::to_string(progress);
  EXPECT_GE(seen.size(), 4u) << "the run did not move on under load; seen" << states << "; last " << last_state
                             << ": " << last_reason;
  std::printf("states seen under load:%s (last: %s: %s); %d status answers, %d abuse answers\n", states.c_str(),
              last_state.c_str(), last_reason.c_str(), answers_during_run, abuse_answers.load());
  // AND every client was answered throughout, abusers with errors, and nobody was dropped
  EXPECT_TRUE(problems.empty()) << problems.size() << " problems, first: " << problems.front();
  EXPECT_GT(answers_during_run, 1000);
  EXPECT_GT(abuse_answers.load(), 0);
  if (rig.ask("status")["running"].boolean()) {
    EXPECT_TRUE(rig.ask("abort")["ok"].boolean());
  }
}

}  // namespace
}  // namespace cdpr::integration
