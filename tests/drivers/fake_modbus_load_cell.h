#pragma once
// A Modbus TCP load cell for loopback tests: a real libmodbus server on
// 127.0.0.1 at a free port chosen by the kernel, serving the register map of
// the load-cell map of drivers/modbus/load_cell_map.h (or registers set
// one by one) from a thread. It can be muted (reads
// requests, never answers) to provoke timeouts, or answer one request late. Bounded: stop() shuts the
// client socket down, so the thread ends even while blocked in a receive.

#include <modbus/modbus.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "drivers/modbus/load_cell_map.h"

namespace cdpr::drivers::modbus::test {

class FakeModbusLoadCell {
 public:
  // Serves `register_count` holding and input registers from address 0.
  explicit FakeModbusLoadCell(int register_count = 16) {
    context_ = modbus_new_tcp("127.0.0.1", 0);
    mapping_ = modbus_mapping_new(0, 0, register_count, register_count);
    listener_ = modbus_tcp_listen(context_, 1);
    sockaddr_in address{};
    socklen_t length = sizeof(address);
    ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length);
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeModbusLoadCell() { stop(); }

  int port() const { return port_; }
  // The value the transmitter shows (its unit, before the map's scale) laid out by `map`.
  void set(double shown_value, bool stable, bool error = false, const LoadCellMap& map = LoadCellMap{}) {
    const RegisterSpan span = register_span(map);
    std::uint16_t registers[kMaxSpanRegisters] = {};
    encode_load_cell(map, shown_value, stable, error, registers);
    set_registers(span.first, {registers, registers + span.count});
  }
  // Raw register values from `address` on (a vendor's layout typed in from its manual).
  void set_registers(int address, std::initializer_list<std::uint16_t> values) {
    set_registers(address, std::vector<std::uint16_t>(values));
  }
  void set_registers(int address, const std::vector<std::uint16_t>& values) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < values.size(); ++i) {
      mapping_->tab_registers[address + i] = values[i];
      mapping_->tab_input_registers[address + i] = values[i];
    }
  }
  void mute(bool muted) { muted_ = muted; }
  // The next reply is sent this late (a busy device or a congested link).
  void delay_next_reply(std::chrono::milliseconds delay) { next_reply_delay_ms_ = static_cast<int>(delay.count()); }
  // Closes the present client connection (the server then accepts anew).
  void drop_client() {
    const int client = client_.load();
    if (client >= 0) ::shutdown(client, SHUT_RDWR);
    for (int i = 0; i < 200 && client_.load() == client; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  int requests() const { return requests_; }

  void stop() {
    if (!thread_.joinable()) return;
    stopping_ = true;
    ::shutdown(listener_, SHUT_RDWR);
    const int client = client_.load();
    if (client >= 0) ::shutdown(client, SHUT_RDWR);
    thread_.join();
    ::close(listener_);
    modbus_close(context_);
    modbus_mapping_free(mapping_);
    modbus_free(context_);
  }

 private:
  void serve() {
    // One client at a time; accept again after it leaves (reconnect tests).
    while (!stopping_) {
      int listener = listener_;
      const int client = modbus_tcp_accept(context_, &listener);
      if (client < 0) return;
      client_ = client;
      std::uint8_t query[MODBUS_TCP_MAX_ADU_LENGTH];
      for (;;) {
        const int length = modbus_receive(context_, query);
        if (length < 0) break;  // client gone or stop()
        if (length == 0) continue;
        ++requests_;
        if (muted_) continue;
        if (const int delay_ms = next_reply_delay_ms_.exchange(0); delay_ms > 0) {
          std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
        }
        std::lock_guard<std::mutex> lock(mutex_);
        modbus_reply(context_, query, length, mapping_);
      }
      client_ = -1;
      ::close(client);
    }
  }

  modbus_t* context_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  int listener_ = -1;
  int port_ = 0;
  std::atomic<int> client_{-1};
  std::atomic<bool> muted_{false};
  std::atomic<bool> stopping_{false};
  std::atomic<int> requests_{0};
  std::atomic<int> next_reply_delay_ms_{0};
  std::mutex mutex_;
  std::thread thread_;
};

}  // namespace cdpr::drivers::modbus::test
