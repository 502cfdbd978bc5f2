#pragma once
// CiA 301 SDO client for one server node (default SDO: requests on
// 0x600 + node, responses on 0x580 + node): expedited and segmented upload
// and download, one transfer at a time, toggle bit checked, abort codes
// decoded into the error, a transfer without an answer for timeout_us is
// aborted (abort 0x05040000 sent to the server).
//
// Non-blocking and clock-free: start_*() queues the first request, the
// owner hands every received frame to on_frame() and sends what poll()
// returns, once per control cycle; nothing here waits. Up to
// kMaxSdoBytes per transfer; no allocation after construction except for
// the error text of a failed transfer.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "drivers/can/can_frame.h"
#include "hal/clock.h"

namespace cdpr::drivers::can {

constexpr std::uint32_t kSdoRequestBase = 0x600;
constexpr std::uint32_t kSdoResponseBase = 0x580;
constexpr std::size_t kMaxSdoBytes = 64;

class SdoClient {
 public:
  enum class State { kIdle, kBusy, kDone, kFailed };

  SdoClient(int node_id, hal::TimeUs timeout_us) : node_id_(node_id), timeout_us_(timeout_us) {}

  // Starts writing `size` bytes (1..kMaxSdoBytes, little-endian values) to
  // index:subindex: expedited up to 4 bytes, segmented above.
  // Precondition: !busy().
  void start_download(std::uint16_t index, std::uint8_t subindex, const std::uint8_t* bytes, std::size_t size,
                      hal::TimeUs now_us);
  // The same for an unsigned value of `size` bytes (1, 2 or 4).
  void start_download_value(std::uint16_t index, std::uint8_t subindex, std::uint32_t value, std::size_t size,
                            hal::TimeUs now_us);
  // Starts reading index:subindex.
  void start_upload(std::uint16_t index, std::uint8_t subindex, hal::TimeUs now_us);

  // A frame from the bus. true: it was this server's SDO response (consumed).
  bool on_frame(const CanFrame& frame, hal::TimeUs now_us);
  // The frame to send now, if any (a request, a segment, or an abort after
  // a timeout or a protocol error).
  std::optional<CanFrame> poll(hal::TimeUs now_us);

  State state() const { return state_; }
  bool busy() const { return state_ == State::kBusy; }
  // Back to idle after kDone or kFailed.
  void clear() { if (state_ != State::kBusy) state_ = State::kIdle; }

  // Uploaded data (kDone after an upload).
  std::size_t size() const { return size_; }
  const std::uint8_t* bytes() const { return buffer_.data(); }
  // The uploaded bytes as a little-endian unsigned value (first 4 bytes).
  std::uint32_t value() const;
  // Why the transfer failed: "node 3 SDO read 0x1018:01: abort 0x06020000
  // (object does not exist in the object dictionary)".
  const std::string& error() const { return error_; }
  // The server's abort code of a failed transfer; 0 for a local failure.
  std::uint32_t abort_code() const { return abort_code_; }

 private:
  enum class Phase { kInitiate, kSegment };

  void begin(bool upload, std::uint16_t index, std::uint8_t subindex, hal::TimeUs now_us);
  void queue(const CanFrame& frame, hal::TimeUs now_us);
  void queue_segment(hal::TimeUs now_us);
  void fail(const std::string& why, std::uint32_t abort_code_to_send, std::uint32_t server_abort);
  void handle_upload(const CanFrame& frame, hal::TimeUs now_us);
  void handle_download(const CanFrame& frame, hal::TimeUs now_us);
  CanFrame request(std::uint8_t command) const;

  int node_id_;
  hal::TimeUs timeout_us_;
  State state_ = State::kIdle;
  bool upload_ = false;
  Phase phase_ = Phase::kInitiate;
  std::uint16_t index_ = 0;
  std::uint8_t subindex_ = 0;
  std::array<std::uint8_t, kMaxSdoBytes> buffer_{};
  std::size_t size_ = 0;       // bytes to download, or uploaded so far
  std::size_t expected_ = 0;   // upload: size the server announced (0: not announced)
  std::size_t offset_ = 0;     // download: bytes already sent
  bool toggle_ = false;
  std::optional<CanFrame> pending_;
  hal::TimeUs last_activity_us_ = 0;
  std::string error_;
  std::uint32_t abort_code_ = 0;
};

}  // namespace cdpr::drivers::can
