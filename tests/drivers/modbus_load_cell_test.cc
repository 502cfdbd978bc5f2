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

ModbusLoadCellConfig config_for(int port, int slave_id = ModbusLoadCellConfig{}.slave_id) {
  ModbusLoadCellConfig config;
  config.slave_id = slave_id;
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
  // GIVEN a cell at address 4 in low-word-first order, read as input registers
  test::FakeModbusLoadCell server;
  LoadCellMap map;
  map.value_address = 4;
  map.status_address = 6;
  map.byte_order = ByteOrder::kCDAB;
  server.set(812.0, true, false, map);
  fakes::ManualClock clock;
  ModbusLoadCellConfig config = config_for(server.port());
  config.map = map;
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

TEST(ModbusLoadCell, ACellThatNeverAnsweredTimesOutWithAHintToCheckTheUnitId) {
  // GIVEN a device that accepts the connection but ignores our unit id (as a wrong slave_id does)
  test::FakeModbusLoadCell server;
  server.mute(true);
  fakes::ManualClock clock;
  ModbusLoadCell cell(config_for(server.port(), 7), clock);
  ASSERT_TRUE(cell.open().ok());
  // WHEN read
  const auto sample = cell.read();
  // THEN it times out, pointing at slave_id
  ASSERT_FALSE(sample.ok());
  EXPECT_EQ(sample.status().code(), hal::ErrorCode::kTimeout);
  EXPECT_NE(sample.status().message().find("never answered: check that [load_cell] slave_id (7) is the device's unit id"),
            std::string::npos)
      << sample.status().message();
  // AND WHEN a cell that did answer falls silent THEN the timeout does not blame the unit id
  server.mute(false);
  ASSERT_TRUE(cell.read().ok());
  server.mute(true);
  const auto silent = cell.read();
  ASSERT_FALSE(silent.ok());
  EXPECT_EQ(silent.status().message().find("slave_id"), std::string::npos) << silent.status().message();
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

TEST(ModbusLoadCell, AnExceptionReplyIsAProtocolErrorAndNotRetried) {
  // GIVEN a map beyond the server's 4 registers and 2 retries allowed
  test::FakeModbusLoadCell server(4);
  fakes::ManualClock clock;
  ModbusLoadCellConfig config = config_for(server.port());
  config.map.value_address = 100;
  config.map.status_address = 102;
  ModbusLoadCell cell(config, clock);
  ASSERT_TRUE(cell.open().ok());
  // WHEN read
  const auto sample = cell.read();
  // THEN the exception (illegal data address) is a protocol error after one request:
  // the device answered, asking again gets the same answer
  EXPECT_EQ(sample.status().code(), hal::ErrorCode::kProtocolError) << sample.status().to_string();
  EXPECT_EQ(server.requests(), 1);
  EXPECT_EQ(cell.counters().exceptions, 1u);
}

// The registers below are typed in from the manuals (docs/fieldbus.md), not
// made with encode_load_cell, so a misreading of the map shows.
TEST(ModbusLoadCell, ReadsAFlintecFt11StyleIndicator) {
  // GIVEN an FT-11: weight int32 at 40001-02 = 1234.5 kg shown with one
  // decimal (12345), status 40003 = D1 "data ok", D2 clear (stable)
  test::FakeModbusLoadCell server;
  server.set_registers(0, {0x0000, 0x3039, 0x0002});
  fakes::ManualClock clock;
  ModbusLoadCellConfig config = config_for(server.port());
  config.map.value_type = ValueType::kInt32;
  config.map.decimals = 1;
  config.map.unit = ForceUnit::kKilogram;
  config.map.status_address = 2;
  config.map.stable = {0x0004, false};  // D2 motion: 1 = not stable
  config.map.error = {0x0002, false};   // D1 data ok: 0 = error
  ModbusLoadCell cell(config, clock);
  ASSERT_TRUE(cell.open().ok());
  // WHEN read THEN kilograms become newtons and "data ok" is not an error
  auto sample = cell.read();
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_NEAR(sample.value().tension_n, 1234.5 * 9.80665, 1e-9);
  EXPECT_TRUE(sample.value().stable);
  // WHEN the weight moves (D2 set) and goes negative THEN unstable, signed
  server.set_registers(0, {0xFFFF, 0xFFF6, 0x0006});
  sample = cell.read();
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_NEAR(sample.value().tension_n, -1.0 * 9.80665, 1e-9);
  EXPECT_FALSE(sample.value().stable);
  // WHEN data ok drops (error code 4 in D13-D15) THEN a device fault
  server.set_registers(2, {0x8000});
  EXPECT_EQ(cell.read().status().code(), hal::ErrorCode::kDeviceFault);
}

TEST(ModbusLoadCell, ReadsALaumasTluStyleTransmitter) {
  // GIVEN a TLU: status 40007, gross weight 40008-09 as a magnitude with its
  // sign in status bit 7, bit 11 "weight stability", bit 0 "load cell error"
  test::FakeModbusLoadCell server(16);
  server.set_registers(6, {0x0800, 0x0001, 0x0002});  // stable, 65538 = 655.38 kg
  fakes::ManualClock clock;
  ModbusLoadCellConfig config = config_for(server.port());
  config.map.value_address = 7;
  config.map.value_type = ValueType::kUint32;
  config.map.decimals = 2;
  config.map.unit = ForceUnit::kKilogram;
  config.map.status_address = 6;
  config.map.stable = {0x0800, true};
  config.map.error = {0x001F, true};
  config.map.sign_mask = 0x0080;
  ModbusLoadCell cell(config, clock);
  ASSERT_TRUE(cell.open().ok());
  // WHEN read THEN one request covers 40007-40009 and the weight is in newtons
  auto sample = cell.read();
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_NEAR(sample.value().tension_n, 655.38 * 9.80665, 1e-9);
  EXPECT_TRUE(sample.value().stable);
  EXPECT_EQ(server.requests(), 1);
  // WHEN the sign bit is set and stability lost THEN negative and unstable
  server.set_registers(6, {0x0080});
  sample = cell.read();
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_NEAR(sample.value().tension_n, -655.38 * 9.80665, 1e-9);
  EXPECT_FALSE(sample.value().stable);
  // WHEN the cell-error bit is set THEN a device fault
  server.set_registers(6, {0x0801});
  EXPECT_EQ(cell.read().status().code(), hal::ErrorCode::kDeviceFault);
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

TEST(ModbusConfig, UnitIdentifierRangesDependOnTheTransport) {
  ModbusLoadCellConfig config;
  // RTU: 1..247; 0 is broadcast (nobody answers a read), 248..255 reserved
  config.endpoint = "rtu:/dev/ttyS0";
  for (const int id : {1, 247}) {
    config.slave_id = id;
    EXPECT_EQ(validate(config), "") << id;
  }
  for (const int id : {0, 248, 255}) {
    config.slave_id = id;
    EXPECT_NE(validate(config), "") << id;
  }
  // TCP: a device addressed directly takes 0 or 255 as well
  config.endpoint = "tcp:127.0.0.1:502";
  for (const int id : {0, 1, 247, 255}) {
    config.slave_id = id;
    EXPECT_EQ(validate(config), "") << id;
  }
  for (const int id : {-1, 248, 256}) {
    config.slave_id = id;
    EXPECT_NE(validate(config), "") << id;
  }
}

TEST(ModbusLoadCell, TalksToATcpDeviceAsUnit255) {
  // GIVEN a TCP device (libmodbus' server answers any unit) and the driver set to unit 255
  test::FakeModbusLoadCell server;
  server.set(42.0, true);
  fakes::ManualClock clock;
  ModbusLoadCell cell(config_for(server.port(), 255), clock);
  // WHEN opened and read THEN the reading comes through
  ASSERT_TRUE(cell.open().ok());
  const auto sample = cell.read();
  ASSERT_TRUE(sample.ok()) << sample.status().to_string();
  EXPECT_DOUBLE_EQ(sample.value().tension_n, 42.0);
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
