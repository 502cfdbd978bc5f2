// The load-cell reader thread: read() never waits for the bus, a silent
// device becomes a fault within the configured timeout, a device that
// reports a fault is one at once. Logic with a behavioural fake on a manual
// clock; timing with the real Modbus driver against a silent TCP peer and a
// silent RTU peer (a pseudo-terminal nobody answers on).

#include "drivers/common/load_cell_reader.h"

#include <pty.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "../fakes/fake_load_cell.h"
#include "../fakes/manual_clock.h"
#include "drivers/clock/monotonic_clock.h"
#include "drivers/modbus/modbus_load_cell.h"
#include "fake_modbus_load_cell.h"

namespace cdpr::drivers {
namespace {

using Clock = std::chrono::steady_clock;

bool wait_for_transactions(const LoadCellReader& reader, unsigned long long count) {
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (reader.transactions() < count) {
    if (Clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// Moves the manual clock on a poll interval at a time until the reader has
// completed `count` transactions.
bool step_until_transactions(const LoadCellReader& reader, fakes::ManualClock& clock, unsigned long long count) {
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (reader.transactions() < count) {
    if (Clock::now() > deadline) return false;
    clock.advance_ms(20);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

TEST(LoadCellReader, KeepsTheLastReadingUntilTheFaultTimeoutThenSaysWhy) {
  // GIVEN a cell at 300 N behind a reader with a 1 s fault timeout
  fakes::ManualClock clock(10'000'000);
  fakes::FakeLoadCell cell(clock);
  cell.set_tension(300.0);
  LoadCellReader reader(cell, clock, {20'000, 1'000'000, 500'000});
  ASSERT_TRUE(reader.open().ok());
  ASSERT_TRUE(wait_for_transactions(reader, 1));
  auto reading = reader.read();
  ASSERT_TRUE(reading.ok()) << reading.status().to_string();
  EXPECT_EQ(reading.value().tension_n, 300.0);
  EXPECT_EQ(reading.value().time_us, 10'000'000);
  // WHEN the cell stops answering
  cell.fail_always(hal::Status(hal::ErrorCode::kTimeout, "cell: no reply after 3 tries"));
  ASSERT_TRUE(step_until_transactions(reader, clock, 2));
  // THEN within the timeout the last reading comes back, same time stamp
  reading = reader.read();
  ASSERT_TRUE(reading.ok());
  EXPECT_EQ(reading.value().time_us, 10'000'000);
  // AND past it the failure is reported with its cause and the silence
  ASSERT_LT(clock.now_us(), 11'000'000);
  clock.set_us(11'000'001);
  reading = reader.read();
  EXPECT_EQ(reading.status().code(), hal::ErrorCode::kTimeout);
  EXPECT_NE(reading.status().message().find("no reply after 3 tries"), std::string::npos) << reading.status().message();
  EXPECT_NE(reading.status().message().find("no good reading for 1000 ms"), std::string::npos);
  // WHEN the cell reports a fault of its own THEN that is reported at once
  const unsigned long long before = reader.transactions();
  cell.fail_always(hal::Status(hal::ErrorCode::kDeviceFault, "cell: error bit"));
  ASSERT_TRUE(step_until_transactions(reader, clock, before + 2));
  EXPECT_EQ(reader.read().status().code(), hal::ErrorCode::kDeviceFault);
  reader.close();
  EXPECT_FALSE(cell.is_open());
  EXPECT_EQ(reader.read().status().code(), hal::ErrorCode::kInvalidState);
}

TEST(LoadCellReader, BeforeTheFirstReadingSaysNoReadingYet) {
  // GIVEN a cell that cannot be opened
  fakes::ManualClock clock(0);
  fakes::FakeLoadCell cell(clock);
  cell.fail_open(hal::Status(hal::ErrorCode::kNotConnected, "cell: connection refused"));
  LoadCellReader reader(cell, clock, {20'000, 1'000'000, 500'000});
  ASSERT_TRUE(reader.open().ok());
  ASSERT_TRUE(wait_for_transactions(reader, 1));
  // WHEN read within the timeout THEN "no reading yet" with the cause
  auto reading = reader.read();
  EXPECT_EQ(reading.status().code(), hal::ErrorCode::kTimeout);
  EXPECT_NE(reading.status().message().find("no reading yet (not connected: cell: connection refused)"),
            std::string::npos)
      << reading.status().message();
  // WHEN past the timeout THEN the cause's own code
  clock.set_us(1'000'001);
  EXPECT_EQ(reader.read().status().code(), hal::ErrorCode::kNotConnected);
  // WHEN the cell comes back THEN the reader reconnects on its own
  cell.fail_open(hal::Status::Ok());
  cell.set_tension(12.0);
  clock.advance_ms(500);
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (!reader.read().ok() && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(reader.read().value().tension_n, 12.0);
}

// Reads every millisecond for `duration`: the longest read() call, and when
// (after `since`) the first error came, if one did.
struct Watch {
  std::chrono::microseconds longest_call{0};
  std::chrono::milliseconds first_error_after{-1};
  std::string first_error;
};

Watch watch(LoadCellReader& reader, Clock::time_point since, std::chrono::milliseconds duration) {
  Watch w;
  const auto end = Clock::now() + duration;
  while (Clock::now() < end) {
    const auto start = Clock::now();
    const auto reading = reader.read();
    const auto took = std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - start);
    w.longest_call = std::max(w.longest_call, took);
    if (!reading.ok() && w.first_error_after.count() < 0) {
      w.first_error_after = std::chrono::duration_cast<std::chrono::milliseconds>(start - since);
      w.first_error = reading.status().to_string();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return w;
}

TEST(LoadCellReader, ASilentTcpPeerNeverBlocksReadAndIsAFaultWithinItsTimeout) {
  // GIVEN the Modbus driver (200 ms x 3 tries) behind a reader with a 300 ms fault timeout, reading
  modbus::test::FakeModbusLoadCell server;
  server.set(100.0, true);
  MonotonicClock clock;
  modbus::ModbusLoadCellConfig config;
  config.endpoint = "tcp:127.0.0.1:" + std::to_string(server.port());
  modbus::ModbusLoadCell cell(config, clock);
  LoadCellReader reader(cell, clock, {20'000, 300'000, 1'000'000});
  ASSERT_TRUE(reader.open().ok());
  ASSERT_TRUE(wait_for_transactions(reader, 2));
  ASSERT_TRUE(reader.read().ok());
  // WHEN the peer stops answering
  const auto muted = Clock::now();
  server.mute(true);
  const Watch w = watch(reader, muted, std::chrono::milliseconds(1500));
  // THEN no read() call waited for the bus, and the fault came after the
  // timeout (counted from the last reading, up to one poll interval before
  // the peer fell silent), within the timeout plus one transaction (3 x 200 ms)
  EXPECT_LT(w.longest_call.count(), 5'000);
  EXPECT_GE(w.first_error_after.count(), 300 - 20);
  EXPECT_LE(w.first_error_after.count(), 300 + 600 + 100);
  EXPECT_NE(w.first_error.find("timeout"), std::string::npos) << w.first_error;
  // WHEN it answers again THEN readings come back
  server.mute(false);
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  while (!reader.read().ok() && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_TRUE(reader.read().ok());
}

TEST(LoadCellReader, ASilentRtuPeerNeverBlocksReadAndIsAFaultWithinItsTimeout) {
  // GIVEN a serial line (a pty) with nobody answering, the driver on it behind a reader
  int master = -1;
  int slave = -1;
  char name[128];
  ASSERT_EQ(openpty(&master, &slave, name, nullptr, nullptr), 0);
  MonotonicClock clock;
  modbus::ModbusLoadCellConfig config;
  config.endpoint = std::string("rtu:") + name;
  modbus::ModbusLoadCell cell(config, clock);
  LoadCellReader reader(cell, clock, {20'000, 300'000, 1'000'000});
  // WHEN opened and read for 1.5 s
  const auto opened = Clock::now();
  ASSERT_TRUE(reader.open().ok());
  const Watch w = watch(reader, opened, std::chrono::milliseconds(1500));
  // THEN read() never waited, and "no reading yet" turned into the timeout fault in time
  EXPECT_LT(w.longest_call.count(), 5'000);
  EXPECT_GE(w.first_error_after.count(), 0);
  const auto faulted = reader.read();
  EXPECT_EQ(faulted.status().code(), hal::ErrorCode::kTimeout) << faulted.status().to_string();
  EXPECT_NE(faulted.status().message().find("no good reading"), std::string::npos) << faulted.status().message();
  reader.close();
  close(master);
  close(slave);
}

}  // namespace
}  // namespace cdpr::drivers
