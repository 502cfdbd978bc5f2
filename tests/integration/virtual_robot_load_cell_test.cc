// The virtual robot's Modbus load cell runs on its physics thread, so no
// client may stall it: not one that sends a request byte by byte and stops,
// not one that floods requests and never reads the replies, not one that
// sends garbage. The daemon's driver keeps getting its readings meanwhile.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../fakes/manual_clock.h"
#include "drivers/modbus/modbus_load_cell.h"
#include "virtual-robot/modbus_tcp_server.h"

namespace cdpr::virtual_robot {
namespace {

int connect_to_port(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  EXPECT_EQ(connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)), 0);
  return fd;
}

// "Read 3 holding registers at 0 from unit 1", Modbus TCP.
constexpr std::uint8_t kReadRequest[] = {0, 1, 0, 0, 0, 6, 1, 3, 0, 0, 0, 3};

// True when the server closed `fd` within `wait_ms` (whatever it sent first is skipped).
bool closed_by_server(int fd, int wait_ms) {
  char sink[4096];
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(wait_ms);
  while (std::chrono::steady_clock::now() < deadline) {
    pollfd entry{fd, POLLIN, 0};
    if (poll(&entry, 1, 50) <= 0) continue;
    const ssize_t n = recv(fd, sink, sizeof(sink), 0);
    if (n == 0 || (n < 0 && errno == ECONNRESET)) return true;
  }
  return false;
}

TEST(VirtualRobotLoadCell, SlowGreedyOrGarbageClientsNeverStallThePhysicsThread) {
  // GIVEN the load cell served by a loop like the virtual robot's physics
  // thread, which times every service() call
  VirtualLoadCell device(LoadCellServerOptions{});
  device.set_reading(702.5, true, false);
  auto server = ModbusTcpServer::listen(0, device);
  ASSERT_TRUE(server.ok()) << server.status().to_string();
  ModbusTcpServer& cell = *server.value();
  std::atomic<bool> stop{false};
  std::atomic<long long> longest_service_us{0};
  std::thread physics([&] {
    std::vector<pollfd> fds;
    while (!stop.load()) {
      fds.clear();
      cell.append_poll_fds(fds);
      poll(fds.data(), fds.size(), 2);
      const auto start = std::chrono::steady_clock::now();
      cell.service(fds, std::chrono::duration_cast<std::chrono::microseconds>(
                            std::chrono::steady_clock::now().time_since_epoch()).count());
      const long long took_us =
          std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - start).count();
      if (took_us > longest_service_us.load()) longest_service_us.store(took_us);
    }
  });

  // WHEN one client sends the first byte of a request and then nothing,
  const int slow = connect_to_port(cell.port());
  ASSERT_EQ(send(slow, kReadRequest, 1, MSG_NOSIGNAL), 1);
  // one floods requests and never reads a reply,
  const int greedy = connect_to_port(cell.port());
  for (int i = 0; i < 20000; ++i) {
    if (send(greedy, kReadRequest, sizeof(kReadRequest), MSG_NOSIGNAL | MSG_DONTWAIT) <= 0) break;
  }
  // one sends a header announcing a 65 KiB request,
  const int garbage = connect_to_port(cell.port());
  const std::uint8_t huge_header[] = {0, 1, 0, 0, 0xFF, 0xFF, 1, 3};
  ASSERT_EQ(send(garbage, huge_header, sizeof(huge_header), MSG_NOSIGNAL), static_cast<ssize_t>(sizeof(huge_header)));
  // and the daemon's driver reads the load cell meanwhile
  fakes::ManualClock clock(1'000'000);
  drivers::modbus::ModbusLoadCellConfig config;
  config.endpoint = "tcp:127.0.0.1:" + std::to_string(cell.port());
  drivers::modbus::ModbusLoadCell driver(config, clock);
  ASSERT_TRUE(driver.open().ok());
  for (int i = 0; i < 5; ++i) {
    const auto reading = driver.read();
    // THEN every reading arrives
    ASSERT_TRUE(reading.ok()) << reading.status().to_string();
    EXPECT_FLOAT_EQ(reading.value().tension_n, 702.5f);
  }
  // AND the garbage sender is put out
  EXPECT_TRUE(closed_by_server(garbage, 2000));
  driver.close();
  stop.store(true);
  physics.join();
  // AND no service() call took long enough to hold up the physics (libmodbus'
  // own receive waited 500 ms for the rest of the slow client's request)
  EXPECT_LT(longest_service_us.load(), 200'000);
  close(slow);
  close(greedy);
  close(garbage);
}

}  // namespace
}  // namespace cdpr::virtual_robot
