#include "drivers/modbus/modbus_load_cell.h"

#include <modbus/modbus.h>

#include <cerrno>
#include <charconv>

#include "drivers/common/posix_status.h"

namespace cdpr::drivers::modbus {
namespace {

struct TcpEndpoint {
  std::string host;
  std::string port;
};

bool parse_tcp(const std::string& rest, TcpEndpoint& out) {
  const std::size_t colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == rest.size()) return false;
  int port = 0;
  const char* first = rest.data() + colon + 1;
  const char* last = rest.data() + rest.size();
  const auto [end, ec] = std::from_chars(first, last, port);
  if (ec != std::errc() || end != last || port <= 0 || port > 65535) return false;
  out.host = rest.substr(0, colon);
  out.port = rest.substr(colon + 1);
  return true;
}

// A Modbus exception reply (function code | 0x80), as libmodbus reports it.
bool is_exception(int error_number) {
  return error_number > MODBUS_ENOBASE && error_number < MODBUS_ENOBASE + MODBUS_EXCEPTION_MAX;
}

}  // namespace

std::string validate(const ModbusLoadCellConfig& c) {
  TcpEndpoint tcp;
  if (c.endpoint.starts_with("tcp:")) {
    if (!parse_tcp(c.endpoint.substr(4), tcp)) return "endpoint '" + c.endpoint + "': expected tcp:<host>:<port>";
  } else if (c.endpoint.starts_with("rtu:")) {
    if (c.endpoint.size() == 4) return "endpoint 'rtu:' names no serial device";
    if (c.baud <= 0) return "baud must be positive";
    if (c.parity != 'N' && c.parity != 'E' && c.parity != 'O') return "parity must be N, E or O";
    if (c.data_bits < 5 || c.data_bits > 8) return "data_bits must be 5..8";
    if (c.stop_bits != 1 && c.stop_bits != 2) return "stop_bits must be 1 or 2";
  } else {
    return "endpoint '" + c.endpoint + "': expected tcp:<host>:<port> or rtu:<device>";
  }
  if (c.endpoint.starts_with("rtu:") && (c.slave_id < 1 || c.slave_id > 247)) {
    return "slave_id " + std::to_string(c.slave_id) + " on RTU must be 1..247 (0 is broadcast, 248..255 reserved)";
  }
  if (c.endpoint.starts_with("tcp:") && !((c.slave_id >= 0 && c.slave_id <= 247) || c.slave_id == 255)) {
    return "slave_id " + std::to_string(c.slave_id) + " on TCP must be 0..247 or 255";
  }
  if (std::string problem = validate(c.map); !problem.empty()) return problem;
  if (c.response_timeout_us <= 0) return "response timeout must be positive";
  if (c.retries < 0 || c.retries > 10) return "retries must be 0..10";
  return {};
}

hal::Status modbus_error_status(int error_number, const std::string& device, const std::string& operation) {
  hal::ErrorCode code;
  switch (error_number) {
    case EMBBADCRC:
    case EMBBADDATA:
      code = hal::ErrorCode::kCorruptData;
      break;
    case EMBXILFUN:
    case EMBXILADD:
    case EMBXILVAL:
    case EMBXSFAIL:
    case EMBXACK:
    case EMBXSBUSY:
    case EMBXNACK:
    case EMBXMEMPAR:
    case EMBXGPATH:
    case EMBXGTAR:
    case EMBBADEXC:
    case EMBUNKEXC:
    case EMBMDATA:
    case EMBBADSLAVE:
      code = hal::ErrorCode::kProtocolError;
      break;
    case EBADF:
      code = hal::ErrorCode::kNotConnected;
      break;
    default:
      code = error_code_from_errno(error_number);
      break;
  }
  return hal::Status(code, device + ": " + operation + ": " + modbus_strerror(error_number));
}

ModbusLoadCell::ModbusLoadCell(ModbusLoadCellConfig config, const hal::Clock& clock)
    : config_(std::move(config)), clock_(clock) {}

ModbusLoadCell::~ModbusLoadCell() { close(); }

hal::Status ModbusLoadCell::open() {
  close();
  if (std::string problem = validate(config_); !problem.empty()) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "load cell: " + problem);
  }
  TcpEndpoint tcp;
  tcp_ = parse_tcp(config_.endpoint.substr(4), tcp) && config_.endpoint.starts_with("tcp:");
  if (tcp_) {
    context_ = modbus_new_tcp_pi(tcp.host.c_str(), tcp.port.c_str());
  } else {
    context_ = modbus_new_rtu(config_.endpoint.substr(4).c_str(), config_.baud, config_.parity, config_.data_bits,
                              config_.stop_bits);
  }
  if (context_ == nullptr) return modbus_error_status(errno, config_.endpoint, "create context");
  const auto seconds = static_cast<std::uint32_t>(config_.response_timeout_us / 1'000'000);
  const auto micros = static_cast<std::uint32_t>(config_.response_timeout_us % 1'000'000);
  if (modbus_set_slave(context_, config_.slave_id) != 0 ||
      modbus_set_response_timeout(context_, seconds, micros) != 0 ||
      modbus_set_byte_timeout(context_, seconds, micros) != 0) {
    const hal::Status s = modbus_error_status(errno, config_.endpoint, "configure");
    close();
    return s;
  }
  return connect();
}

hal::Status ModbusLoadCell::connect() {
  if (modbus_connect(context_) != 0) {
    connected_ = false;
    return modbus_error_status(errno, config_.endpoint, "connect");
  }
  connected_ = true;
  return hal::Status::Ok();
}

void ModbusLoadCell::close() {
  if (context_ == nullptr) return;
  if (connected_) modbus_close(context_);
  modbus_free(context_);
  context_ = nullptr;
  connected_ = false;
}

hal::Status ModbusLoadCell::try_read(std::uint16_t (&registers)[kMaxSpanRegisters]) {
  ++counters_.requests;
  const RegisterSpan span = register_span(config_.map);
  const int n = config_.register_kind == RegisterKind::kHolding
                    ? modbus_read_registers(context_, span.first, span.count, registers)
                    : modbus_read_input_registers(context_, span.first, span.count, registers);
  if (n == span.count) return hal::Status::Ok();
  if (n >= 0) {
    ++counters_.other_errors;
    return hal::Status(hal::ErrorCode::kProtocolError, config_.endpoint + ": short reply (" + std::to_string(n) +
                                                           " registers)");
  }
  const int error_number = errno;
  const hal::Status error = modbus_error_status(error_number, config_.endpoint, "read registers");
  if (is_exception(error_number)) {
    ++counters_.exceptions;
    return error;
  }
  switch (error.code()) {
    case hal::ErrorCode::kTimeout: ++counters_.timeouts; break;
    case hal::ErrorCode::kCorruptData: ++counters_.corrupt; break;
    default: ++counters_.other_errors; break;
  }
  return error;
}

hal::Result<hal::TensionSample> ModbusLoadCell::read() {
  if (context_ == nullptr) return hal::Status(hal::ErrorCode::kInvalidState, "load cell: not open");
  hal::Status last;
  const int tries = 1 + config_.retries;
  for (int attempt = 0; attempt < tries; ++attempt) {
    if (!connected_) {
      ++counters_.reconnects;
      last = connect();
      if (!last.ok()) continue;
    }
    std::uint16_t registers[kMaxSpanRegisters] = {};
    const unsigned long long exceptions_before = counters_.exceptions;
    last = try_read(registers);
    answered_ = answered_ || last.ok() || counters_.exceptions != exceptions_before;
    if (last.ok()) {
      const hal::Result<LoadCellReading> decoded = decode_load_cell(config_.map, registers);
      if (!decoded.ok()) {
        return hal::Status(decoded.status().code(), config_.endpoint + ": " + decoded.status().message());
      }
      return hal::TensionSample{decoded.value().tension_n, decoded.value().stable, clock_.now_us()};
    }
    // An exception is the device's considered answer (no such register,
    // function not supported): asking again gets the same one.
    if (counters_.exceptions != exceptions_before) return last;
    // A late reply must not be taken for the next answer. On a serial line
    // flushing drops it. A TCP stream may deliver it after any flush, and
    // then every later request would read its predecessor's reply (libmodbus
    // refuses the transaction id: "Invalid data", forever); a new connection
    // cannot carry it, so TCP reconnects. A broken connection is rebuilt on
    // the next try as well.
    const bool stale_reply_possible =
        last.code() == hal::ErrorCode::kTimeout || last.code() == hal::ErrorCode::kCorruptData;
    if (stale_reply_possible && !tcp_) modbus_flush(context_);
    if ((stale_reply_possible && tcp_) || last.code() == hal::ErrorCode::kNotConnected ||
        last.code() == hal::ErrorCode::kIoError) {
      modbus_close(context_);
      connected_ = false;
    }
  }
  std::string text = last.message() + " (after " + std::to_string(tries) + " tries, " +
                     std::to_string(config_.response_timeout_us / 1000) + " ms timeout each)";
  // A gateway or a bus with the wrong unit id answers nothing at all: the
  // most common cause of a cell that never replied.
  if (last.code() == hal::ErrorCode::kTimeout && !answered_) {
    text += "; the cell never answered: check that [load_cell] slave_id (" + std::to_string(config_.slave_id) +
            ") is the device's unit id";
  }
  return hal::Status(last.code(), text);
}

}  // namespace cdpr::drivers::modbus
