#pragma once
// The virtual load cell on Modbus RTU (Modbus over Serial Line v1.02) through
// a pseudo-terminal: the daemon opens the pty's slave side, found through a
// symbolic link (e.g. <dir>/load_cell.tty), as its serial port.
//
// As a device on an RS-485 line: a frame is taken once its length is known
// from the function code (8 bytes for 0x01-0x06, 9 + byte count for
// 0x0F/0x10) or, for other functions, after a silence of kFrameGapUs; a
// frame with a bad CRC is dropped with everything received with it (the
// device waits for the next silence, as after line noise); a frame for
// another address gets no answer, nor does broadcast (address 0). Replies
// carry the CRC (low byte first) and wait out the reply latency.
// Faults: kSilent answers nothing; kGarbage sends noise of the reply's
// length; kDisconnected closes the pty (the daemon's port reads end of file
// or EIO, as when a USB adapter is pulled) and removes the link until the
// fault is cleared, when a new pty is linked in its place.
// Owns the pty and the link. Not thread-safe.

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "hal/status.h"
#include "virtual-robot/modbus_transport.h"
#include "virtual-robot/virtual_load_cell.h"

namespace cdpr::virtual_robot {

// Modbus RTU's CRC-16 (polynomial 0xA001 reflected, initial 0xFFFF).
std::uint16_t modbus_rtu_crc(const std::uint8_t* data, std::size_t size);

class ModbusRtuServer final : public ModbusTransport {
 public:
  static constexpr hal::TimeUs kFrameGapUs = 5'000;

  // Creates the pty and links `link_path` to its slave side. `cell` must
  // outlive the server.
  static hal::Result<std::unique_ptr<ModbusRtuServer>> open(const std::string& link_path, VirtualLoadCell& cell);
  ~ModbusRtuServer() override;
  ModbusRtuServer(const ModbusRtuServer&) = delete;
  ModbusRtuServer& operator=(const ModbusRtuServer&) = delete;

  std::string endpoint() const override { return "rtu:" + link_path_; }
  void append_poll_fds(std::vector<pollfd>& fds) const override;
  void service(const std::vector<pollfd>& fds, hal::TimeUs now_us) override;

  unsigned long long dropped_frames() const { return dropped_frames_; }

 private:
  struct Reply {
    hal::TimeUs due_us;
    std::vector<std::uint8_t> bytes;
  };

  ModbusRtuServer(std::string link_path, VirtualLoadCell& cell) : link_path_(std::move(link_path)), cell_(cell) {}
  hal::Status open_pty();
  void close_pty();
  // Takes the whole frames at the front of pending_.
  void take_frames(hal::TimeUs now_us, bool gap_passed);
  void handle_frame(const std::uint8_t* frame, std::size_t size, hal::TimeUs now_us);

  std::string link_path_;
  VirtualLoadCell& cell_;
  int master_ = -1;
  int slave_ = -1;  // kept open so the master never sees a hang-up between clients
  std::vector<std::uint8_t> pending_;
  hal::TimeUs last_byte_us_ = 0;
  std::deque<Reply> replies_;
  unsigned long long dropped_frames_ = 0;
};

}  // namespace cdpr::virtual_robot
