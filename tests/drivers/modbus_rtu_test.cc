// Modbus RTU through a pseudo-terminal: the driver opens the pty's slave side
// as its serial port; a fake cell on the master side answers read requests
// well, with a broken CRC, or with noise. Checks that CRC and framing errors
// become kCorruptData after the retries and that good replies still decode.

#include <poll.h>
#include <pty.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../fakes/manual_clock.h"
#include "../fakes/modbus_crc.h"
#include "drivers/modbus/modbus_load_cell.h"

namespace cdpr::drivers::modbus {
namespace {

class FakeRtuCell {
 public:
  enum class Mode { kGood, kBadCrc, kNoise };

  FakeRtuCell() {
    char name[128];
    EXPECT_EQ(::openpty(&master_, &slave_, name, nullptr, nullptr), 0);
    path_ = name;
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeRtuCell() {
    stop_ = true;
    thread_.join();
    ::close(master_);
    ::close(slave_);
  }
  const std::string& path() const { return path_; }
  void set_mode(Mode mode) { mode_ = mode; }
  int requests() const { return requests_; }

 private:
  void serve() {
    std::vector<std::uint8_t> request;
    while (!stop_) {
      pollfd pfd{master_, POLLIN, 0};
      if (::poll(&pfd, 1, 10) <= 0) continue;
      std::uint8_t byte[64];
      const ssize_t n = ::read(master_, byte, sizeof(byte));
      if (n <= 0) continue;
      request.insert(request.end(), byte, byte + n);
      if (request.size() < 8) continue;  // read-registers request: 8 bytes
      ++requests_;
      reply(request[0], request[1]);
      request.clear();
    }
  }

  void reply(std::uint8_t slave, std::uint8_t function) {
    // 1234.5 N as float32 0x449A5000, high word first; status: stable.
    std::vector<std::uint8_t> frame = {slave, function, 6, 0x44, 0x9A, 0x50, 0x00, 0x00, 0x01};
    const std::uint16_t crc = fakes::modbus_crc16(frame.data(), frame.size());
    frame.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    frame.push_back(static_cast<std::uint8_t>(crc >> 8));
    if (mode_ == Mode::kBadCrc) frame.back() ^= 0x5A;
    if (mode_ == Mode::kNoise) frame = {0x13, 0x37, 0x00, 0xFF, 0x42};
    (void)::write(master_, frame.data(), frame.size());
  }

  int master_ = -1;
  int slave_ = -1;
  std::string path_;
  std::atomic<Mode> mode_{Mode::kGood};
  std::atomic<bool> stop_{false};
  std::atomic<int> requests_{0};
  std::thread thread_;
};

ModbusLoadCellConfig rtu_config(const std::string& path) {
  ModbusLoadCellConfig config;
  config.endpoint = "rtu:" + path;
  config.baud = 115200;
  config.response_timeout_us = 50'000;
  config.retries = 1;
  return config;
}

TEST(ModbusRtu, GoodReplyDecodesBadCrcAndNoiseAreCorrupt) {
  // GIVEN a fake cell on a pty answering well
  FakeRtuCell fake;
  fakes::ManualClock clock;
  ModbusLoadCell cell(rtu_config(fake.path()), clock);
  const hal::Status opened = cell.open();
  ASSERT_TRUE(opened.ok()) << opened.to_string();
  // WHEN read THEN the tension arrives
  const auto good = cell.read();
  ASSERT_TRUE(good.ok()) << good.status().to_string();
  EXPECT_FLOAT_EQ(good.value().tension_n, 1234.5f);
  EXPECT_TRUE(good.value().stable);
  // WHEN the CRC of every reply is broken THEN corrupt data after 2 tries
  fake.set_mode(FakeRtuCell::Mode::kBadCrc);
  const auto bad_crc = cell.read();
  ASSERT_FALSE(bad_crc.ok());
  EXPECT_EQ(bad_crc.status().code(), hal::ErrorCode::kCorruptData) << bad_crc.status().to_string();
  EXPECT_NE(bad_crc.status().message().find("2 tries"), std::string::npos) << bad_crc.status().message();
  EXPECT_GE(cell.counters().corrupt, 2u);
  // WHEN replies are noise THEN an error, never a value
  fake.set_mode(FakeRtuCell::Mode::kNoise);
  const auto noise = cell.read();
  ASSERT_FALSE(noise.ok());
  const hal::ErrorCode code = noise.status().code();
  EXPECT_TRUE(code == hal::ErrorCode::kCorruptData || code == hal::ErrorCode::kProtocolError)
      << noise.status().to_string();
  // WHEN good again THEN reads recover
  fake.set_mode(FakeRtuCell::Mode::kGood);
  const auto again = cell.read();
  ASSERT_TRUE(again.ok()) << again.status().to_string();
}

}  // namespace
}  // namespace cdpr::drivers::modbus
