// Loopback: the Modbus load cell driver against a real libmodbus TCP server
// on 127.0.0.1 serving the register map.

#include "drivers/modbus/modbus_load_cell.h"

#include <modbus/modbus.h>

#include <chrono>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "../fakes/manual_clock.h"
#include "fake_modbus_load_cell.h"

namespace cdpr::drivers::modbus {
namespace {

ModbusLoadCellConfig config_for(int port) {
  ModbusLoadCellConfig config;
  config.endpoint = "tcp:127.0.0.1:" + std::to_string(port);
  config.response_timeout_us = 50'000;
  config.retries = 2;
  return config;
}

TEST(ModbusLoadCell, ReadsTensionAndStableBit) {
  // GIVEN a cell at 1234.5 N, stable, and the clock at 7 s
  test::FakeModbusLoadCell server;
  server.set(1234.5f, true);
  fakes::ManualClock clock(7'000'000);
  ModbusLoadCell cell(config_for(server.port()), clock);
  ASSERT_TRUE(cell.open().ok());
  // WHEN read
  const hal::Result<hal::TensionSample> sample = cell.read();
  // THEN tension, stable flag and time stamp come through
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_FLOAT_EQ(sample.value().tension_n, 1234.5f);
  EXPECT_TRUE(sample.value().stable);
  EXPECT_EQ(sample.value().time_us, 7'000'000);
  // WHEN the value changes to unstable THEN the next read shows it
  server.set(-3.25f, false);
  const hal::Result<hal::TensionSample> next = cell.read();
  ASSERT_TRUE(next.ok());
  EXPECT_FLOAT_EQ(next.value().tension_n, -3.25f);
  EXPECT_FALSE(next.value().stable);
}

TEST(ModbusLoadCell, HonoursWordOrderBaseAndInputRegisters) {
  // GIVEN a cell at base 4 in low-word-first order, read as input registers
  test::FakeModbusLoadCell server(4);
  server.set(812.0f, true, false, WordOrder::kLowWordFirst);
  fakes::ManualClock clock;
  ModbusLoadCellConfig config = config_for(server.port());
  config.first_register = 4;
  config.word_order = WordOrder::kLowWordFirst;
  config.register_kind = RegisterKind::kInput;
  ModbusLoadCell cell(config, clock);
  ASSERT_TRUE(cell.open().ok());
  // WHEN read THEN the float is assembled right
  const auto sample = cell.read();
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_FLOAT_EQ(sample.value().tension_n, 812.0f);
}

TEST(ModbusLoadCell, SilentServerTimesOutAfterRetries) {
  // GIVEN a server that stops answering
  test::FakeModbusLoadCell server;
  server.set(100.0f, true);
  fakes::ManualClock clock;
  ModbusLoadCell cell(config_for(server.port()), clock);
  ASSERT_TRUE(cell.open().ok());
  ASSERT_TRUE(cell.read().ok());
  const int before = server.requests();
  server.mute(true);
  // WHEN read
  const auto start = std::chrono::steady_clock::now();
  const auto sample = cell.read();
  const auto elapsed = std::chrono::steady_clock::now() - start;
  // THEN a timeout after 3 tries (1 + 2 retries), in about 3 x 50 ms, saying so
  ASSERT_FALSE(sample.ok());
  EXPECT_EQ(sample.status().code(), hal::ErrorCode::kTimeout) << sample.status().to_string();
  EXPECT_NE(sample.status().message().find("3 tries"), std::string::npos) << sample.status().message();
  EXPECT_EQ(server.requests() - before, 3);
  EXPECT_EQ(cell.counters().timeouts, 3u);
  EXPECT_LT(elapsed, std::chrono::milliseconds(1000));
  // WHEN the server answers again THEN reads recover (late replies flushed)
  server.mute(false);
  const auto again = cell.read();
  ASSERT_TRUE(again.ok()) << again.status().to_string();
  EXPECT_FLOAT_EQ(again.value().tension_n, 100.0f);
}

TEST(ModbusLoadCell, ALateReplyOverTcpIsNeverTakenForALaterAnswer) {
  // GIVEN a cell whose next reply comes after the driver's 100 ms timeout
  test::FakeModbusLoadCell server;
  server.set(250.0f, true);
  fakes::ManualClock clock;
  ModbusLoadCellConfig config = config_for(server.port());
  config.response_timeout_us = 100'000;
  ModbusLoadCell cell(config, clock);
  ASSERT_TRUE(cell.open().ok());
  ASSERT_TRUE(cell.read().ok());
  server.delay_next_reply(std::chrono::milliseconds(150));
  // WHEN read, and read again a few times
  const auto late = cell.read();
  // THEN the read succeeds on a retry and every later read gets its own answer, not its predecessor's
  ASSERT_TRUE(late.ok()) << late.status().to_string();
  EXPECT_FLOAT_EQ(late.value().tension_n, 250.0f);
  EXPECT_GE(cell.counters().timeouts, 1u);
  for (int k = 0; k < 5; ++k) {
    server.set(300.0f + static_cast<float>(k), true);
    const auto sample = cell.read();
    ASSERT_TRUE(sample.ok()) << "read " << k << ": " << sample.status().to_string();
    EXPECT_FLOAT_EQ(sample.value().tension_n, 300.0f + static_cast<float>(k));
  }
  EXPECT_EQ(cell.counters().corrupt, 0u);
}

TEST(ModbusLoadCell, DeviceErrorBitAndNanAreDeviceFaults) {
  test::FakeModbusLoadCell server;
  fakes::ManualClock clock;
  ModbusLoadCell cell(config_for(server.port()), clock);
  ASSERT_TRUE(cell.open().ok());
  server.set(10.0f, true, /*error=*/true);
  EXPECT_EQ(cell.read().status().code(), hal::ErrorCode::kDeviceFault);
  server.set(std::nanf(""), true);
  EXPECT_EQ(cell.read().status().code(), hal::ErrorCode::kDeviceFault);
}

TEST(ModbusLoadCell, IllegalAddressIsAProtocolError) {
  // GIVEN a map beyond the server's registers
  test::FakeModbusLoadCell server(0, 4);
  fakes::ManualClock clock;
  ModbusLoadCellConfig config = config_for(server.port());
  config.first_register = 100;
  ModbusLoadCell cell(config, clock);
  ASSERT_TRUE(cell.open().ok());
  // WHEN read THEN the Modbus exception becomes a protocol error, not retried forever
  const auto sample = cell.read();
  EXPECT_EQ(sample.status().code(), hal::ErrorCode::kProtocolError) << sample.status().to_string();
}

TEST(ModbusLoadCell, NoServerIsNotConnectedAndReadBeforeOpenIsInvalidState) {
  // GIVEN a port where nobody listens (a server started and stopped)
  int port = 0;
  {
    test::FakeModbusLoadCell server;
    port = server.port();
  }
  fakes::ManualClock clock;
  ModbusLoadCell cell(config_for(port), clock);
  EXPECT_EQ(cell.read().status().code(), hal::ErrorCode::kInvalidState);
  EXPECT_EQ(cell.open().code(), hal::ErrorCode::kNotConnected);
}

TEST(ModbusLoadCell, ReconnectsAfterTheServerDropsTheConnection) {
  // GIVEN a working connection
  test::FakeModbusLoadCell server;
  server.set(55.0f, true);
  fakes::ManualClock clock;
  ModbusLoadCell cell(config_for(server.port()), clock);
  ASSERT_TRUE(cell.open().ok());
  ASSERT_TRUE(cell.read().ok());
  // WHEN the server restarts its side of the connection (accepts anew)
  server.drop_client();
  // THEN the next read reconnects within its retries and succeeds
  const auto sample = cell.read();
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_FLOAT_EQ(sample.value().tension_n, 55.0f);
  EXPECT_GE(cell.counters().reconnects, 1u);
}

TEST(ModbusConfig, RejectsBadEndpoints) {
  ModbusLoadCellConfig config;
  config.endpoint = "udp:1.2.3.4:502";
  EXPECT_NE(validate(config), "");
  config.endpoint = "tcp:localhost:99999";
  EXPECT_NE(validate(config), "");
  config.endpoint = "rtu:/dev/ttyS0";
  config.parity = 'X';
  EXPECT_NE(validate(config), "");
  config.parity = 'E';
  EXPECT_EQ(validate(config), "");
}

TEST(ModbusErrors, TranslatesLibmodbusErrno) {
  EXPECT_EQ(modbus_error_status(ETIMEDOUT, "d", "op").code(), hal::ErrorCode::kTimeout);
  EXPECT_EQ(modbus_error_status(EMBBADCRC, "d", "op").code(), hal::ErrorCode::kCorruptData);
  EXPECT_EQ(modbus_error_status(EMBXILADD, "d", "op").code(), hal::ErrorCode::kProtocolError);
  EXPECT_EQ(modbus_error_status(ECONNRESET, "d", "op").code(), hal::ErrorCode::kNotConnected);
  EXPECT_NE(modbus_error_status(EMBBADCRC, "dev", "read").message().find("dev: read:"), std::string::npos);
}

}  // namespace
}  // namespace cdpr::drivers::modbus
