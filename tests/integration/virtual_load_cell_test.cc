// The virtual robot's load cell is as strict as a real transmitter, and
// written apart from the daemon's driver, so the two check each other: unit
// identifiers (RTU: silence; TCP: gateway exception 0x0B), read-only
// registers, the register ranges and functions of each vendor map, reply
// latency; every vendor map read end to end through the daemon's preset, on
// TCP and on RTU; and a peer neither side wrote (mbpoll) reading the
// virtual cell.

#include <modbus/modbus.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/clock/monotonic_clock.h"
#include "drivers/modbus/modbus_load_cell.h"
#include "drivers/modbus/load_cell_presets.h"
#include "virtual-robot/modbus_rtu_server.h"
#include "virtual-robot/modbus_tcp_server.h"

namespace cdpr::virtual_robot {
namespace {

constexpr double kKgf = 9.80665;

// A virtual cell served on its own thread, as the virtual robot's loop does.
class ServedCell {
 public:
  ServedCell(const LoadCellServerOptions& options, bool rtu) : device_(options) {
    char pattern[] = "/tmp/cdpr-vcell-XXXXXX";
    dir_ = mkdtemp(pattern);
    if (rtu) {
      auto server = ModbusRtuServer::open(dir_ + "/load_cell.tty", device_);
      EXPECT_TRUE(server.ok()) << server.status().to_string();
      transport_ = std::move(server.value());
    } else {
      auto server = ModbusTcpServer::listen(0, device_);
      EXPECT_TRUE(server.ok()) << server.status().to_string();
      transport_ = std::move(server.value());
    }
    thread_ = std::thread([this] {
      std::vector<pollfd> fds;
      while (!stop_.load()) {
        fds.clear();
        transport_->append_poll_fds(fds);
        poll(fds.data(), fds.size(), 1);
        transport_->service(fds, clock_.now_us());
      }
    });
  }
  ~ServedCell() {
    stop_.store(true);
    thread_.join();
    transport_.reset();
    std::filesystem::remove_all(dir_);
  }
  // Between requests only (the serving thread reads the table).
  VirtualLoadCell& device() { return device_; }
  std::string endpoint() const { return transport_->endpoint(); }

 private:
  VirtualLoadCell device_;
  std::string dir_;
  std::unique_ptr<ModbusTransport> transport_;
  drivers::MonotonicClock clock_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// A raw libmodbus client on `endpoint` ("tcp:127.0.0.1:<port>" or "rtu:<path>").
modbus_t* client_for(const std::string& endpoint, int unit) {
  modbus_t* ctx = endpoint.starts_with("tcp:")
                      ? modbus_new_tcp("127.0.0.1", std::stoi(endpoint.substr(endpoint.rfind(':') + 1)))
                      : modbus_new_rtu(endpoint.substr(4).c_str(), 19200, 'N', 8, 1);
  modbus_set_slave(ctx, unit);
  modbus_set_response_timeout(ctx, 0, 200'000);
  EXPECT_EQ(modbus_connect(ctx), 0) << modbus_strerror(errno);
  return ctx;
}

drivers::modbus::ModbusLoadCellConfig driver_config(const std::string& endpoint, LoadCellModel model, int unit) {
  drivers::modbus::ModbusLoadCellConfig c;
  c.endpoint = endpoint;
  c.slave_id = unit;
  c.map = *drivers::modbus::load_cell_preset(to_string(model));
  if (model != LoadCellModel::kLegacyFloat32) c.map.decimals = kShownDecimals;
  c.response_timeout_us = 100'000;
  c.retries = 0;
  return c;
}

class EachTransport : public ::testing::TestWithParam<bool> {};
INSTANTIATE_TEST_SUITE_P(VirtualLoadCell, EachTransport, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "Rtu" : "Tcp"; });

TEST_P(EachTransport, AnswersOnlyItsOwnUnitIdentifier) {
  // GIVEN a cell at unit 5
  LoadCellServerOptions options;
  options.unit_id = 5;
  ServedCell cell(options, GetParam());
  cell.device().set_reading(100.0, true, false);
  drivers::MonotonicClock clock;
  // WHEN the driver asks unit 6
  drivers::modbus::ModbusLoadCell wrong(driver_config(cell.endpoint(), LoadCellModel::kLegacyFloat32, 6), clock);
  ASSERT_TRUE(wrong.open().ok());
  const auto refused = wrong.read();
  // THEN on RTU nobody answers (timeout); on TCP the gateway says its target did not respond
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), GetParam() ? hal::ErrorCode::kTimeout : hal::ErrorCode::kProtocolError)
      << refused.status().to_string();
  wrong.close();
  // WHEN it asks unit 5 THEN the reading comes
  drivers::modbus::ModbusLoadCell right(driver_config(cell.endpoint(), LoadCellModel::kLegacyFloat32, 5), clock);
  ASSERT_TRUE(right.open().ok());
  const auto reading = right.read();
  ASSERT_TRUE(reading.ok()) << reading.status().to_string();
  EXPECT_NEAR(reading.value().tension_n, 100.0, 1e-4);
}

TEST_P(EachTransport, RefusesWritesAndReadsOutsideItsMap) {
  // GIVEN an FT-11 (holding registers 0..31, function 0x03 only)
  LoadCellServerOptions options;
  options.model = LoadCellModel::kFlintecFt11;
  ServedCell cell(options, GetParam());
  cell.device().set_reading(1000.0, true, false);
  modbus_t* ctx = client_for(cell.endpoint(), 1);
  std::uint16_t before[3] = {};
  ASSERT_EQ(modbus_read_registers(ctx, 0, 3, before), 3) << modbus_strerror(errno);
  // WHEN a register is written, one or several THEN exception 02 and nothing changes
  EXPECT_EQ(modbus_write_register(ctx, 0, 1234), -1);
  EXPECT_EQ(errno, EMBXILADD) << modbus_strerror(errno);
  const std::uint16_t values[2] = {1, 2};
  EXPECT_EQ(modbus_write_registers(ctx, 0, 2, values), -1);
  EXPECT_EQ(errno, EMBXILADD) << modbus_strerror(errno);
  std::uint16_t after[3] = {};
  ASSERT_EQ(modbus_read_registers(ctx, 0, 3, after), 3);
  EXPECT_EQ(std::vector<std::uint16_t>(after, after + 3), std::vector<std::uint16_t>(before, before + 3));
  // WHEN reading past the map THEN exception 02; input registers THEN exception 01
  std::uint16_t sink[8];
  EXPECT_EQ(modbus_read_registers(ctx, 30, 4, sink), -1);
  EXPECT_EQ(errno, EMBXILADD) << modbus_strerror(errno);
  EXPECT_EQ(modbus_read_input_registers(ctx, 0, 2, sink), -1);
  EXPECT_EQ(errno, EMBXILFUN) << modbus_strerror(errno);
  modbus_close(ctx);
  modbus_free(ctx);
}

// The daemon's presets and the virtual transmitters are one list by name:
// a preset without a virtual counterpart would go untested, a virtual
// model without a preset could not be configured.
TEST(VirtualLoadCell, EveryPresetHasAVirtualTransmitterAndEveryTransmitterAPreset) {
  for (const drivers::modbus::LoadCellPreset& preset : drivers::modbus::load_cell_presets()) {
    EXPECT_TRUE(parse_load_cell_model(preset.name)) << preset.name << " has no model in load_cell_models.cc";
  }
  for (const LoadCellModel model : all_load_cell_models()) {
    EXPECT_TRUE(drivers::modbus::load_cell_preset(to_string(model))) << to_string(model) << " has no preset";
  }
}

TEST_P(EachTransport, EveryVendorMapReadsRightThroughItsPreset) {
  for (const drivers::modbus::LoadCellPreset& preset : drivers::modbus::load_cell_presets()) {
    SCOPED_TRACE(preset.name);
    const std::optional<LoadCellModel> parsed = parse_load_cell_model(preset.name);
    ASSERT_TRUE(parsed);
    const LoadCellModel model = *parsed;
    // GIVEN a cell of this model and the daemon's driver set up from the model's preset
    LoadCellServerOptions options;
    options.model = model;
    ServedCell cell(options, GetParam());
    drivers::MonotonicClock clock;
    drivers::modbus::ModbusLoadCell driver(driver_config(cell.endpoint(), model, 1), clock);
    ASSERT_TRUE(driver.open().ok());
    // The indicators show 0.01 kg: the reading is good to half of that.
    const double resolution_n = model == LoadCellModel::kLegacyFloat32 ? 1e-3 : 0.005 * kKgf + 1e-9;
    // WHEN it carries 7000 N, stable THEN the driver reads 7000 N, stable
    cell.device().set_reading(7000.0, true, false);
    auto reading = driver.read();
    ASSERT_TRUE(reading.ok()) << reading.status().to_string();
    EXPECT_NEAR(reading.value().tension_n, 7000.0, resolution_n);
    EXPECT_TRUE(reading.value().stable);
    // WHEN -50 N, moving THEN negative (the TLU's sign bit) and unstable
    cell.device().set_reading(-50.0, false, false);
    reading = driver.read();
    ASSERT_TRUE(reading.ok()) << reading.status().to_string();
    EXPECT_NEAR(reading.value().tension_n, -50.0, resolution_n);
    EXPECT_FALSE(reading.value().stable);
    // WHEN the transmitter reports an error THEN a device fault
    cell.device().set_reading(100.0, true, true);
    EXPECT_EQ(driver.read().status().code(), hal::ErrorCode::kDeviceFault);
  }
}

TEST_P(EachTransport, RepliesAfterItsLatency) {
  // GIVEN a cell that answers 40 ms after a request
  LoadCellServerOptions options;
  options.reply_latency_us = 40'000;
  ServedCell cell(options, GetParam());
  cell.device().set_reading(10.0, true, false);
  drivers::MonotonicClock clock;
  drivers::modbus::ModbusLoadCell driver(driver_config(cell.endpoint(), LoadCellModel::kLegacyFloat32, 1), clock);
  ASSERT_TRUE(driver.open().ok());
  // WHEN read THEN the reply takes at least the latency, and not much more
  const auto start = std::chrono::steady_clock::now();
  const auto reading = driver.read();
  const auto took_ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(reading.ok()) << reading.status().to_string();
  EXPECT_GE(took_ms, 40);
  EXPECT_LT(took_ms, 95);
}

TEST_P(EachTransport, GarbageRepliesAreRefusedAsCorrupt) {
  // GIVEN a cell that answers noise
  ServedCell cell(LoadCellServerOptions{}, GetParam());
  cell.device().set_fault(DeviceFault::kGarbage);
  drivers::MonotonicClock clock;
  drivers::modbus::ModbusLoadCell driver(driver_config(cell.endpoint(), LoadCellModel::kLegacyFloat32, 1), clock);
  ASSERT_TRUE(driver.open().ok());
  // WHEN read THEN refused, never a reading
  for (int i = 0; i < 5; ++i) {
    const auto reading = driver.read();
    ASSERT_FALSE(reading.ok());
    EXPECT_NE(reading.status().code(), hal::ErrorCode::kDeviceFault) << reading.status().to_string();
  }
}

// Runs mbpoll (a Modbus master neither side of this project wrote) and
// returns its output; empty when it is not installed.
std::string run_mbpoll(const std::string& arguments) {
  if (!std::filesystem::exists("/usr/bin/mbpoll")) return {};
  std::string output;
  FILE* pipe = popen(("/usr/bin/mbpoll " + arguments + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return {};
  char buffer[512];
  while (fgets(buffer, sizeof(buffer), pipe) != nullptr) output += buffer;
  pclose(pipe);
  return output;
}

TEST_P(EachTransport, MbpollReadsTheVendorRegistersAsTheManualLaysThemOut) {
  // GIVEN a TLU at unit 3 carrying -1000 N (= 101.97 kg, sign in the status register)
  LoadCellServerOptions options;
  options.model = LoadCellModel::kLaumasTlu;
  options.unit_id = 3;
  ServedCell cell(options, GetParam());
  cell.device().set_reading(-1000.0, true, false);
  const std::string endpoint = cell.endpoint();
  const std::string where = endpoint.starts_with("tcp:")
                                ? "-m tcp -p " + endpoint.substr(endpoint.rfind(':') + 1) + " 127.0.0.1"
                                : "-m rtu -b 19200 -P none " + endpoint.substr(4);
  // WHEN mbpoll reads 40007-40009 once (reference 7, 1-based as in the manual)
  const std::string output = run_mbpoll("-a 3 -t 4 -r 7 -c 3 -1 -o 1 " + where);
  if (output.empty()) GTEST_SKIP() << "mbpoll not installed";
  // THEN status = stable | gross negative | net negative, gross = 10197 in two words
  const long count = std::lround(1000.0 / kKgf * 100.0);
  EXPECT_NE(output.find("[7]: \t" + std::to_string((1 << 11) | (1 << 7) | (1 << 8))), std::string::npos) << output;
  EXPECT_NE(output.find("[8]: \t" + std::to_string(count >> 16)), std::string::npos) << output;
  EXPECT_NE(output.find("[9]: \t" + std::to_string(count & 0xFFFF)), std::string::npos) << output;
  // AND a write from mbpoll is refused with the exception the manual lists
  const std::string write = run_mbpoll("-a 3 -t 4 -r 8 -1 -o 1 " + where + " 5");
  EXPECT_NE(write.find("Illegal data address"), std::string::npos) << write;
  // AND another unit gets nothing (RTU) or the gateway's exception (TCP)
  const std::string other = run_mbpoll("-a 4 -t 4 -r 7 -c 1 -1 -o 0.3 " + where);
  EXPECT_NE(other.find(GetParam() ? "timed out" : "Target device failed to respond"), std::string::npos) << other;
}

}  // namespace
}  // namespace cdpr::virtual_robot
