#include "drivers/can/sdo_client.h"

#include <algorithm>
#include <cstdio>

#include "drivers/can/sdo_abort.h"

namespace cdpr::drivers::can {
namespace {

// Command specifiers (bits 7-5 of byte 0), CiA 301 SDO protocols.
constexpr std::uint8_t kCcsDownloadSegment = 0 << 5;
constexpr std::uint8_t kCcsDownloadInitiate = 1 << 5;
constexpr std::uint8_t kCcsUploadInitiate = 2 << 5;
constexpr std::uint8_t kCcsUploadSegment = 3 << 5;
constexpr std::uint8_t kCsAbort = 4 << 5;
constexpr std::uint8_t kScsUploadSegment = 0 << 5;
constexpr std::uint8_t kScsDownloadSegment = 1 << 5;
constexpr std::uint8_t kScsUploadInitiate = 2 << 5;
constexpr std::uint8_t kScsDownloadInitiate = 3 << 5;
constexpr std::uint8_t kToggleBit = 0x10;

std::uint32_t le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

std::string hex(std::uint32_t value, int digits) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%0*X", digits, static_cast<unsigned>(value));
  return text;
}

}  // namespace

CanFrame SdoClient::request(std::uint8_t command) const {
  CanFrame frame;
  frame.id = kSdoRequestBase + static_cast<std::uint32_t>(node_id_);
  frame.len = 8;
  frame.data[0] = command;
  frame.data[1] = static_cast<std::uint8_t>(index_ & 0xFF);
  frame.data[2] = static_cast<std::uint8_t>(index_ >> 8);
  frame.data[3] = subindex_;
  return frame;
}

void SdoClient::begin(bool upload, std::uint16_t index, std::uint8_t subindex, hal::TimeUs now_us) {
  state_ = State::kBusy;
  upload_ = upload;
  phase_ = Phase::kInitiate;
  index_ = index;
  subindex_ = subindex;
  expected_ = 0;
  offset_ = 0;
  toggle_ = false;
  error_.clear();
  abort_code_ = 0;
  last_activity_us_ = now_us;
}

void SdoClient::queue(const CanFrame& frame, hal::TimeUs now_us) {
  pending_ = frame;
  last_activity_us_ = now_us;
}

void SdoClient::start_download(std::uint16_t index, std::uint8_t subindex, const std::uint8_t* bytes, std::size_t size,
                               hal::TimeUs now_us) {
  begin(false, index, subindex, now_us);
  size_ = std::min(size, kMaxSdoBytes);
  std::copy(bytes, bytes + size_, buffer_.begin());
  if (size_ <= 4) {
    // Expedited, size indicated: n = 4 - size unused bytes.
    CanFrame frame = request(static_cast<std::uint8_t>(kCcsDownloadInitiate | (4 - size_) << 2 | 0x03));
    std::copy(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(size_), frame.data.begin() + 4);
    queue(frame, now_us);
    return;
  }
  CanFrame frame = request(kCcsDownloadInitiate | 0x01);  // segmented, size in bytes 4-7
  for (int i = 0; i < 4; ++i) frame.data[4 + i] = static_cast<std::uint8_t>(size_ >> (8 * i));
  queue(frame, now_us);
}

void SdoClient::start_download_value(std::uint16_t index, std::uint8_t subindex, std::uint32_t value, std::size_t size,
                                     hal::TimeUs now_us) {
  const std::uint8_t bytes[4] = {static_cast<std::uint8_t>(value), static_cast<std::uint8_t>(value >> 8),
                                 static_cast<std::uint8_t>(value >> 16), static_cast<std::uint8_t>(value >> 24)};
  start_download(index, subindex, bytes, std::min<std::size_t>(size, 4), now_us);
}

void SdoClient::start_upload(std::uint16_t index, std::uint8_t subindex, hal::TimeUs now_us) {
  begin(true, index, subindex, now_us);
  size_ = 0;
  queue(request(kCcsUploadInitiate), now_us);
}

std::uint32_t SdoClient::value() const {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < std::min<std::size_t>(size_, 4); ++i) value |= static_cast<std::uint32_t>(buffer_[i]) << (8 * i);
  return value;
}

void SdoClient::fail(const std::string& why, std::uint32_t abort_code_to_send, std::uint32_t server_abort) {
  state_ = State::kFailed;
  abort_code_ = server_abort;
  error_ = "node " + std::to_string(node_id_) + " SDO " + (upload_ ? "read " : "write ") + hex(index_, 4) + ":" +
           hex(subindex_, 2) + ": " + why;
  pending_.reset();
  if (abort_code_to_send != 0) {
    CanFrame frame = request(kCsAbort);
    for (int i = 0; i < 4; ++i) frame.data[4 + i] = static_cast<std::uint8_t>(abort_code_to_send >> (8 * i));
    pending_ = frame;
  }
}

bool SdoClient::on_frame(const CanFrame& frame, hal::TimeUs now_us) {
  if (frame.id != kSdoResponseBase + static_cast<std::uint32_t>(node_id_)) return false;
  if (state_ != State::kBusy) return true;  // late answer to an aborted transfer
  if (frame.len != 8) {
    fail("malformed response (" + std::to_string(frame.len) + " bytes)", kSdoAbortCommand, 0);
    return true;
  }
  const std::uint8_t command = frame.data[0] & 0xE0;
  const auto index = static_cast<std::uint16_t>(frame.data[1] | frame.data[2] << 8);
  if (command == kCsAbort) {
    const std::uint32_t code = le32(&frame.data[4]);
    fail("abort " + hex(code, 8) + " (" + sdo_abort_text(code) + ")", 0, code);
    return true;
  }
  const bool initiate_reply = command == kScsUploadInitiate || command == kScsDownloadInitiate;
  if (initiate_reply && (index != index_ || frame.data[3] != subindex_)) {
    fail("response for " + hex(index, 4) + ":" + hex(frame.data[3], 2), kSdoAbortCommand, 0);
    return true;
  }
  if (upload_) {
    handle_upload(frame, now_us);
  } else {
    handle_download(frame, now_us);
  }
  return true;
}

void SdoClient::handle_upload(const CanFrame& frame, hal::TimeUs now_us) {
  const std::uint8_t b0 = frame.data[0];
  if (phase_ == Phase::kInitiate) {
    if ((b0 & 0xE0) != kScsUploadInitiate) return fail("unexpected command " + hex(b0, 2), kSdoAbortCommand, 0);
    if ((b0 & 0x02) != 0) {  // expedited: the data is in bytes 4-7
      size_ = (b0 & 0x01) != 0 ? 4u - ((b0 >> 2) & 0x03) : 4u;
      std::copy(frame.data.begin() + 4, frame.data.begin() + 4 + static_cast<std::ptrdiff_t>(size_), buffer_.begin());
      state_ = State::kDone;
      return;
    }
    expected_ = (b0 & 0x01) != 0 ? le32(&frame.data[4]) : 0;
    if (expected_ > kMaxSdoBytes) {
      return fail(std::to_string(expected_) + " bytes, more than " + std::to_string(kMaxSdoBytes) + " expected",
                  0x05040005, 0);
    }
    phase_ = Phase::kSegment;
    size_ = 0;
    toggle_ = false;
    queue(request(kCcsUploadSegment), now_us);
    return;
  }
  if ((b0 & 0xE0) != kScsUploadSegment) return fail("unexpected command " + hex(b0, 2), kSdoAbortCommand, 0);
  if (((b0 & kToggleBit) != 0) != toggle_) return fail("toggle bit not alternated", kSdoAbortToggle, 0);
  const std::size_t n = 7u - ((b0 >> 1) & 0x07);
  if (size_ + n > kMaxSdoBytes) return fail("more than " + std::to_string(kMaxSdoBytes) + " bytes", 0x05040005, 0);
  std::copy(frame.data.begin() + 1, frame.data.begin() + 1 + static_cast<std::ptrdiff_t>(n), buffer_.begin() + static_cast<std::ptrdiff_t>(size_));
  size_ += n;
  if ((b0 & 0x01) != 0) {  // last segment
    if (expected_ != 0 && size_ != expected_) {
      return fail(std::to_string(size_) + " bytes received, " + std::to_string(expected_) + " announced",
                  kSdoAbortLength, 0);
    }
    state_ = State::kDone;
    return;
  }
  toggle_ = !toggle_;
  CanFrame next = request(static_cast<std::uint8_t>(kCcsUploadSegment | (toggle_ ? kToggleBit : 0)));
  for (int i = 1; i < 8; ++i) next.data[i] = 0;
  queue(next, now_us);
}

void SdoClient::queue_segment(hal::TimeUs now_us) {
  const std::size_t n = std::min<std::size_t>(7, size_ - offset_);
  const bool last = offset_ + n == size_;
  CanFrame frame = request(static_cast<std::uint8_t>(kCcsDownloadSegment | (toggle_ ? kToggleBit : 0) |
                                                     (7 - n) << 1 | (last ? 1 : 0)));
  for (int i = 1; i < 8; ++i) frame.data[i] = 0;
  std::copy(buffer_.begin() + static_cast<std::ptrdiff_t>(offset_), buffer_.begin() + static_cast<std::ptrdiff_t>(offset_ + n),
            frame.data.begin() + 1);
  offset_ += n;
  queue(frame, now_us);
}

void SdoClient::handle_download(const CanFrame& frame, hal::TimeUs now_us) {
  const std::uint8_t b0 = frame.data[0];
  if (phase_ == Phase::kInitiate) {
    if ((b0 & 0xE0) != kScsDownloadInitiate) return fail("unexpected command " + hex(b0, 2), kSdoAbortCommand, 0);
    if (size_ <= 4) {
      state_ = State::kDone;
      return;
    }
    phase_ = Phase::kSegment;
    toggle_ = false;
    queue_segment(now_us);
    return;
  }
  if ((b0 & 0xE0) != kScsDownloadSegment) return fail("unexpected command " + hex(b0, 2), kSdoAbortCommand, 0);
  if (((b0 & kToggleBit) != 0) != toggle_) return fail("toggle bit not alternated", kSdoAbortToggle, 0);
  if (offset_ == size_) {
    state_ = State::kDone;
    return;
  }
  toggle_ = !toggle_;
  queue_segment(now_us);
}

std::optional<CanFrame> SdoClient::poll(hal::TimeUs now_us) {
  if (state_ == State::kBusy && !pending_ && now_us - last_activity_us_ > timeout_us_) {
    fail("no answer within " + std::to_string(timeout_us_ / 1000) + " ms (abort " + hex(kSdoAbortTimeout, 8) + ")",
         kSdoAbortTimeout, 0);
  }
  std::optional<CanFrame> out = pending_;
  if (pending_ && state_ == State::kBusy) last_activity_us_ = now_us;  // the server's time starts now
  pending_.reset();
  return out;
}

}  // namespace cdpr::drivers::can
