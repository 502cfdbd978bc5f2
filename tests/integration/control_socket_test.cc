// The daemon's control socket under concurrent clients, with the daemon
// running against the virtual robot: every request gets its own answer,
// simultaneous presses start exactly one run, and an abort stops it.

#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "virtual_robot_rig.h"

namespace cdpr::integration {
namespace {

TEST(ControlSocket, ConcurrentClientsEachGetTheirAnswersAndStartOneRunOnly) {
  // GIVEN the daemon against the virtual small robot, its CANopen nodes up
  virtual_robot::VirtualRobotOptions options;
  options.preset = sim::Preset::kSmall;
  options.time_scale = 5.0;
  VirtualRobotRig rig(options);
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

  // AND WHEN the operator aborts THEN the run ends failed with the abort as its reason
  EXPECT_TRUE(rig.ask("abort")["ok"].boolean());
  calibctl::JsonValue status = rig.ask("status");
  for (int n = 0; n < 50 && status["running"].boolean(); ++n) {  // the abort state stops the winches first
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    status = rig.ask("status");
  }
  EXPECT_FALSE(status["running"].boolean());
  EXPECT_EQ(status["state"].string(), "failed");
  EXPECT_NE(status["reason"].string().find("abort"), std::string::npos) << status["reason"].string();
  EXPECT_FALSE(rig.ask("show")["present"].boolean());  // nothing committed
}

}  // namespace
}  // namespace cdpr::integration
