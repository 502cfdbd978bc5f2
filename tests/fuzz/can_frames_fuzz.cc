// Fuzz target: CAN frames from the winch nodes, as the daemon receives them:
// raw 16-byte wire records (drivers/can/fd_can_transport.h) on a real socket,
// decoded and dispatched by CanopenWinchBank to its heartbeat consumers and
// CiA 402 drive state machines (drivers/can/canopen.h, cia402_drive.h), with
// the daemon's own calls (enable, targets, update) interleaved.
//
// Input: steps of 17 bytes, one control byte and one wire record. Control
// byte: bits 0-3 advance the clock by that many 10 ms, bit 4 calls enable(),
// bit 5 commands winch (bits 6-7) to a target, then update() runs.
// Promises checked: never a crash; update() never fails on a connected bus
// whatever the records hold (a bad record is counted and skipped); payouts
// are finite; no more frames received than records written.

#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "drivers/can/canopen_winch_bank.h"
#include "drivers/can/fd_can_transport.h"
#include "fuzz_check.h"

namespace {

using namespace cdpr::drivers::can;

CanWinchBankConfig four_winches() {
  CanWinchBankConfig config;
  // Winch 3 has no cable encoder: its drive's position is the payout.
  const int encoders[4] = {11, 12, 13, 0};
  for (int i = 0; i < 4; ++i) config.winches.push_back({i + 1, encoders[i], 1e-4, -2e-5});
  config.max_frames_per_update = 8;  // so records pile up across updates too
  return config;
}

// Throws away what the bank sent, so the socket never fills up.
void drain(int fd) {
  std::uint8_t sink[4096];
  while (::recv(fd, sink, sizeof(sink), MSG_DONTWAIT) > 0) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using cdpr::fuzz::require;
  int fds[2];
  require(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) == 0, "socketpair");
  const int bank_end = fds[0];
  bool connected = false;
  CanopenWinchBank bank(four_winches(), [bank_end, &connected]() -> cdpr::hal::Result<std::unique_ptr<CanTransport>> {
    connected = true;
    return std::unique_ptr<CanTransport>(std::make_unique<FdCanTransport>(bank_end, "fuzz bus"));
  });
  require(bank.open().ok() && connected, "open on a socketpair");
  cdpr::hal::TimeUs now_us = 0;
  std::size_t records = 0;
  constexpr std::size_t kStep = 1 + kWireFrameBytes;
  for (std::size_t at = 0; at < size; at += kStep) {
    const std::uint8_t control = data[at];
    const std::size_t n = size - at - 1 < kWireFrameBytes ? size - at - 1 : kWireFrameBytes;
    if (n > 0) require(::write(fds[1], data + at + 1, n) == static_cast<ssize_t>(n), "write to the socketpair");
    records += n == kWireFrameBytes;
    now_us += 10'000 * (control & 0x0F);
    if (control & 0x10) (void)bank.enable();
    if (control & 0x20) (void)bank.set_target_payout(control >> 6, 0.25 * (control >> 6) - 0.3);
    require(bank.update(now_us).ok(), "update never fails on a connected bus");
    drain(fds[1]);
  }
  for (int i = 0; i < bank.winch_count(); ++i) {
    const cdpr::hal::WinchStatus s = bank.status(i);
    require(std::isfinite(s.payout_m) && std::isfinite(s.target_payout_m), "payouts are finite");
    require(s.heartbeat_age_us >= -1, "heartbeat age is -1 or an age");
  }
  require(bank.counters().frames_rx <= records, "no more frames received than records written");
  ::close(fds[1]);
  return 0;
}
