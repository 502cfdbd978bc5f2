#pragma once
// The independent CANopen peer (tests/peer: node-canopen's SDO server, PDO,
// NMT, heartbeat and EMCY, with only the CiA 402 / CiA 406 device behaviour
// scripted) as a child process serving the daemon's `unix:` CAN transport,
// and a listener on the same bus that decodes what the drives send.
//
// The peer's npm package is installed by `make test` (tests/peer,
// `npm ci`); without it (npm could not reach the registry) the tests skip
// and say so.

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "daemon_process.h"
#include "drivers/can/fd_can_transport.h"
#include "../read_text.h"

namespace cdpr::integration {

class CanopenPeer {
 public:
  // Empty when the peer can run, else why not.
  static std::string unavailable_reason() {
    const std::string peer_dir = std::string(CDPR_SOURCE_DIR) + "/tests/peer";
    if (std::system("node --version >/dev/null 2>&1") != 0) {
      return "node is not installed (make test installs the Debian package nodejs)";
    }
    if (!std::filesystem::exists(peer_dir + "/node_modules/canopen/package.json")) {
      return "the npm package canopen is not installed in " + peer_dir +
             " (make test runs `npm ci` there; was the npm registry unreachable?)";
    }
    return {};
  }

  // Starts `node tests/peer/peer.js` with `options` (vendor quirks, see peer.js).
  explicit CanopenPeer(const std::vector<std::string>& options = {}) {
    using namespace std::chrono_literals;
    char pattern[] = "/tmp/cdpr-canopen-peer-XXXXXX";
    dir = mkdtemp(pattern);
    socket = dir + "/can.sock";
    frame_log = dir + "/frames.log";
    std::vector<std::string> argv{"node", std::string(CDPR_SOURCE_DIR) + "/tests/peer/peer.js", "--socket", socket,
                                  "--frame-log", frame_log};
    argv.insert(argv.end(), options.begin(), options.end());
    process_ = std::make_unique<ChildProcess>(argv, dir + "/peer.log");
    if (!wait_until([&] { return process_->log().find("ready ") != std::string::npos; }, 20s)) {
      ADD_FAILURE() << "the CANopen peer did not start: " << process_->log();
    }
  }
  ~CanopenPeer() {
    process_->signal(SIGTERM);
    process_->wait_exit(std::chrono::seconds(5));
    if (!::testing::Test::HasFailure()) std::filesystem::remove_all(dir);
  }

  std::string endpoint() const { return "unix:" + socket; }
  std::string log() const { return process_->log(); }

  // The frames the bridge logged whose COB-ID is one of `ids`, at most
  // `count` of them, in order ("  12.3 > 601 [8] 2f 60 60 00 01 00 00 00";
  // > from the master, < from a device).
  // Only frames logged from `from_ms` to `to_ms` (ms since the peer started).
  std::string frames(const std::vector<std::uint32_t>& ids, int count, double from_ms = 0.0,
                     double to_ms = 1e12) const {
    std::istringstream lines(test::read_text(frame_log));
    std::string line, out;
    for (int n = 0; n < count && std::getline(lines, line);) {
      std::istringstream fields(line);
      std::string time, direction, id;
      fields >> time >> direction >> id;
      const double ms = std::atof(time.c_str());
      if (ms < from_ms || ms > to_ms) continue;
      const auto cob = static_cast<std::uint32_t>(std::strtoul(id.c_str(), nullptr, 16));
      for (std::uint32_t wanted : ids) {
        if (cob == wanted) {
          out += line + "\n";
          ++n;
          break;
        }
      }
    }
    return out;
  }

  // When the first frame with COB-ID `id` was logged [ms since the peer started], -1 when none.
  double first_frame_ms(std::uint32_t id) const {
    std::istringstream lines(test::read_text(frame_log));
    std::string line;
    while (std::getline(lines, line)) {
      std::istringstream fields(line);
      std::string time, direction, cob;
      fields >> time >> direction >> cob;
      if (std::strtoul(cob.c_str(), nullptr, 16) == id) return std::atof(time.c_str());
    }
    return -1.0;
  }

  std::string dir, socket, frame_log;

 private:
  std::unique_ptr<ChildProcess> process_;
};

// Listens on the peer's bus as another client: the drives' TPDO1 (as the
// daemon maps it: statusword + position actual value) and their EMCYs.
class BusListener {
 public:
  struct Drive {
    bool heard = false;
    std::uint16_t statusword = 0;
    std::int32_t position = 0;
    std::vector<std::uint16_t> emergencies;
  };

  explicit BusListener(const std::string& socket) {
    auto transport = drivers::can::FdCanTransport::connect_unix(socket);
    EXPECT_TRUE(transport.ok()) << transport.status().to_string();
    if (transport.ok()) transport_ = std::move(transport.value());
  }

  // Reads every frame waiting; false when the bus is gone.
  bool poll() {
    if (!transport_) return false;
    drivers::can::CanFrame frame;
    for (;;) {
      auto got = transport_->receive(frame, 0);
      if (!got.ok()) return false;
      if (!got.value()) return true;
      const std::uint32_t node = frame.id & 0x7F;
      if ((frame.id & 0x780) == 0x180 && frame.len == 6) {
        Drive& d = drives[node];
        d.heard = true;
        d.statusword = static_cast<std::uint16_t>(frame.data[0] | frame.data[1] << 8);
        d.position = static_cast<std::int32_t>(static_cast<std::uint32_t>(frame.data[2]) | frame.data[3] << 8 |
                                               frame.data[4] << 16 | static_cast<std::uint32_t>(frame.data[5]) << 24);
      } else if ((frame.id & 0x780) == 0x080 && node != 0 && frame.len == 8) {
        drives[node].emergencies.push_back(static_cast<std::uint16_t>(frame.data[0] | frame.data[1] << 8));
      }
    }
  }

  std::map<std::uint32_t, Drive> drives;

 private:
  std::unique_ptr<drivers::can::FdCanTransport> transport_;
};

// CiA 402 state coding (6.3.1): bits 0-3, 5, 6 of the statusword.
inline bool operation_enabled(std::uint16_t statusword) { return (statusword & 0x6F) == 0x27; }
inline bool quick_stop_active(std::uint16_t statusword) { return (statusword & 0x6F) == 0x07; }

}  // namespace cdpr::integration
