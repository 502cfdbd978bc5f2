#include "drivers/pose/pose_stream_source.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

#include "drivers/common/posix_status.h"
#include "drivers/common/socket_io.h"

namespace cdpr::drivers::pose {

PoseStreamSource::PoseStreamSource(const std::string& endpoint, const hal::Clock& clock,
                                   hal::TimeUs connect_timeout_us)
    : endpoint_(endpoint), connect_timeout_us_(connect_timeout_us), name_("pose stream " + endpoint), clock_(clock) {}

PoseStreamSource::PoseStreamSource(FdConnector connector, std::string name, const hal::Clock& clock)
    : connector_(std::move(connector)), name_(std::move(name)), clock_(clock) {}

PoseStreamSource::~PoseStreamSource() { close(); }

hal::Status PoseStreamSource::open() {
  close();
  hal::Result<int> fd = connector_ ? connector_() : start_connect_endpoint(endpoint_);
  if (!fd.ok()) return hal::Status(fd.status().code(), name_ + ": " + fd.status().message());
  fd_ = fd.value();
  set_nonblocking(fd_);
  connecting_ = !connector_;
  connect_started_us_ = clock_.now_us();
  fill_ = 0;
  discarding_ = false;
  return hal::Status::Ok();
}

void PoseStreamSource::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  connecting_ = false;
}

hal::Status PoseStreamSource::finish_connect() {
  const hal::Result<bool> done = connect_progress(fd_, name_);
  if (done.ok() && done.value()) {
    connecting_ = false;
    return hal::Status::Ok();
  }
  hal::Status failure;
  if (!done.ok()) {
    failure = hal::Status(hal::ErrorCode::kNotConnected, done.status().message());
  } else if (clock_.now_us() - connect_started_us_ > connect_timeout_us_) {
    failure = hal::Status(hal::ErrorCode::kNotConnected,
                          name_ + ": connect not done within " + std::to_string(connect_timeout_us_ / 1000) + " ms");
  } else {
    return hal::Status::Ok();  // still connecting
  }
  close();
  return failure;
}

hal::Status PoseStreamSource::update(hal::TimeUs timeout_us) {
  if (fd_ < 0) return hal::Status(hal::ErrorCode::kInvalidState, name_ + ": not open");
  if (connecting_) {
    if (const hal::Status s = finish_connect(); !s.ok() || connecting_) return s;
  }
  if (timeout_us > 0) {
    const hal::Result<bool> ready = wait_readable(fd_, timeout_us);
    if (!ready.ok()) {
      ++counters_.io_errors;
      return ready.status();
    }
    if (!ready.value()) return hal::Status::Ok();
  }
  for (int i = 0; i < kMaxReadsPerUpdate; ++i) {
    const ssize_t n = ::read(fd_, buffer_.data() + fill_, buffer_.size() - fill_);
    if (n > 0) {
      fill_ += static_cast<std::size_t>(n);
      consume_lines(clock_.now_us());
      continue;
    }
    if (n == 0) {
      close();
      return hal::Status(hal::ErrorCode::kNotConnected, name_ + ": peer closed the stream");
    }
    if (errno == EINTR) continue;
    if (errno == EAGAIN) break;
    ++counters_.io_errors;
    const hal::Status error = status_from_errno(errno, name_, "read");
    close();
    return error;
  }
  return hal::Status::Ok();
}

void PoseStreamSource::consume_lines(hal::TimeUs now_us) {
  std::size_t start = 0;
  for (std::size_t i = 0; i < fill_; ++i) {
    if (buffer_[i] != '\n') continue;
    if (discarding_) {
      discarding_ = false;  // end of the over-long line, already counted
    } else {
      handle_line(std::string_view(buffer_.data() + start, i - start), now_us);
    }
    start = i + 1;
  }
  std::memmove(buffer_.data(), buffer_.data() + start, fill_ - start);
  fill_ -= start;
  if (fill_ == buffer_.size()) {
    // A full buffer without '\n': the line is too long. Count it once and
    // drop bytes up to its end.
    if (!discarding_) {
      ++counters_.rejected_lines;
      last_rejection_ = PoseLineResult::kTooLong;
    }
    discarding_ = true;
    fill_ = 0;
  }
}

void PoseStreamSource::handle_line(std::string_view line, hal::TimeUs now_us) {
  hal::PoseSample sample;
  const PoseLineResult result = parse_pose_line(line, sample);
  if (result == PoseLineResult::kComment) return;
  if (result != PoseLineResult::kSample) {
    ++counters_.rejected_lines;
    last_rejection_ = result;
    return;
  }
  sample.received_us = now_us;
  latest_ = sample;
  ++counters_.samples;
}

}  // namespace cdpr::drivers::pose
