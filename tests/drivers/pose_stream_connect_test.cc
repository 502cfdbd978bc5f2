// The pose stream's connect never waits: open() starts it, update() finishes
// it or gives up after the connect timeout, each call returning at once, so
// the daemon's loop is not held by a peer that does not answer.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "drivers/clock/monotonic_clock.h"
#include "drivers/pose/pose_line.h"
#include "drivers/pose/pose_stream_source.h"

namespace cdpr::drivers::pose {
namespace {

using Clock = std::chrono::steady_clock;

double elapsed_ms(Clock::time_point since) {
  return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
}

// A loopback listener that never accepts, its queue filled: the kernel drops
// further SYNs, so a new connect stays in progress (as to a host that is
// down; outside addresses may be answered by a proxy on test machines).
class StuckListener {
 public:
  StuckListener() {
    listener_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    EXPECT_EQ(::bind(listener_, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
    EXPECT_EQ(::listen(listener_, 0), 0);
    socklen_t length = sizeof(address);
    ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length);
    port_ = ntohs(address.sin_port);
    for (int& filler : fillers_) {
      filler = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
      ::connect(filler, reinterpret_cast<const sockaddr*>(&address), sizeof(address));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ~StuckListener() {
    for (const int filler : fillers_) ::close(filler);
    ::close(listener_);
  }
  int port() const { return port_; }

 private:
  int listener_ = -1;
  int port_ = 0;
  int fillers_[4] = {-1, -1, -1, -1};
};

TEST(PoseStreamConnect, APeerThatNeverAcceptsFailsWithinTheConnectTimeoutWithoutEverWaiting) {
  // GIVEN a TCP endpoint whose connect never completes
  StuckListener stuck;
  MonotonicClock clock;
  PoseStreamSource source("tcp:127.0.0.1:" + std::to_string(stuck.port()), clock, 200'000);
  // WHEN opened and updated until it gives up
  auto start = Clock::now();
  const hal::Status opened = source.open();
  double slowest_ms = elapsed_ms(start);
  const auto began = Clock::now();
  hal::Status status = opened;
  while (status.ok() && elapsed_ms(began) < 2000) {
    start = Clock::now();
    status = source.update(0);
    slowest_ms = std::max(slowest_ms, elapsed_ms(start));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  // THEN no call waited, and the failure came after the connect timeout and a little
  EXPECT_LT(slowest_ms, 5.0);
  EXPECT_EQ(status.code(), hal::ErrorCode::kNotConnected) << status.to_string();
  EXPECT_GE(elapsed_ms(began), 200.0);
  EXPECT_LT(elapsed_ms(began), 200.0 + 100.0);
  EXPECT_NE(status.message().find("connect not done within 200 ms"), std::string::npos) << status.message();
}

TEST(PoseStreamConnect, ATcpPeerThatAcceptsDeliversPoses) {
  // GIVEN a TCP listener on loopback
  const int listener = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(listener, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  socklen_t length = sizeof(address);
  ::getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length);
  MonotonicClock clock;
  PoseStreamSource source("tcp:127.0.0.1:" + std::to_string(ntohs(address.sin_port)), clock, 1'000'000);
  // WHEN opened, accepted and sent a pose
  ASSERT_TRUE(source.open().ok());
  const int peer = ::accept(listener, nullptr, nullptr);
  ASSERT_GE(peer, 0);
  hal::PoseSample sent;
  sent.platform_world = {1.0, 2.0, 3.0};
  sent.world_R_platform = {1.0, 0.0, 0.0, 0.0};
  sent.valid = true;
  const std::string line = format_pose_line(sent);
  ASSERT_EQ(::write(peer, line.data(), line.size()), static_cast<ssize_t>(line.size()));
  // THEN updates finish the connect and deliver it
  const auto deadline = Clock::now() + std::chrono::seconds(2);
  while (!source.latest() && Clock::now() < deadline) {
    ASSERT_TRUE(source.update(1'000).ok());
  }
  ASSERT_TRUE(source.latest().has_value());
  EXPECT_EQ(source.latest()->platform_world.z, 3.0);
  ::close(peer);
  ::close(listener);
}

}  // namespace
}  // namespace cdpr::drivers::pose
