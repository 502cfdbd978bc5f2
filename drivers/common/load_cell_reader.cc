#include "drivers/common/load_cell_reader.h"

#include <chrono>

namespace cdpr::drivers {
namespace {

std::string milliseconds(hal::TimeUs duration_us) { return std::to_string(duration_us / 1000) + " ms"; }

}  // namespace

LoadCellReader::LoadCellReader(hal::LoadCell& inner, const hal::Clock& clock, LoadCellReaderOptions options)
    : inner_(inner), clock_(clock), options_(options) {}

LoadCellReader::~LoadCellReader() { close(); }

hal::Status LoadCellReader::open() {
  close();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = false;
    opened_us_ = clock_.now_us();
    latest_.reset();
    last_failure_ = hal::Status::Ok();
  }
  thread_ = std::thread([this] { run(); });
  return hal::Status::Ok();
}

void LoadCellReader::close() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool LoadCellReader::sleep_until(hal::TimeUs deadline_us) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (stopping_) return false;
    const hal::TimeUs left_us = deadline_us - clock_.now_us();
    if (left_us <= 0) return true;
    wake_.wait_for(lock, std::chrono::microseconds(left_us));
  }
}

void LoadCellReader::run() {
  bool open = false;
  while (true) {
    const hal::TimeUs started_us = clock_.now_us();
    if (!open) {
      const hal::Status opened = inner_.open();
      open = opened.ok();
      if (!open) {
        {
          std::lock_guard<std::mutex> lock(mutex_);
          last_failure_ = opened;
          last_failure_us_ = clock_.now_us();
          ++transactions_;
        }
        if (!sleep_until(started_us + options_.reconnect_interval_us)) break;
        continue;
      }
    }
    const hal::Result<hal::TensionSample> reading = inner_.read();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++transactions_;
      if (reading.ok()) {
        latest_ = reading.value();
        last_failure_ = hal::Status::Ok();
      } else {
        last_failure_ = reading.status();
        last_failure_us_ = clock_.now_us();
      }
    }
    if (!reading.ok() && (reading.status().code() == hal::ErrorCode::kNotConnected ||
                          reading.status().code() == hal::ErrorCode::kInvalidState)) {
      inner_.close();
      open = false;
    }
    if (!sleep_until(started_us + options_.poll_interval_us)) break;
  }
  inner_.close();
}

hal::Result<hal::TensionSample> LoadCellReader::read() {
  const hal::TimeUs now_us = clock_.now_us();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!thread_.joinable()) return hal::Status(hal::ErrorCode::kInvalidState, "load cell: not open");
  if (last_failure_.code() == hal::ErrorCode::kDeviceFault) return last_failure_;
  const hal::TimeUs good_since_us = latest_ ? latest_->time_us : opened_us_;
  const hal::TimeUs silent_us = now_us - good_since_us;
  if (silent_us <= options_.fault_timeout_us) {
    if (latest_) return *latest_;
    return hal::Status(hal::ErrorCode::kTimeout,
                       "load cell: no reading yet" + (last_failure_.ok() ? std::string() : " (" + last_failure_.to_string() + ")"));
  }
  const std::string cause = last_failure_.ok() ? "no answer yet to the request in flight" : last_failure_.message();
  return hal::Status(last_failure_.ok() ? hal::ErrorCode::kTimeout : last_failure_.code(),
                     cause + "; no good reading for " + milliseconds(silent_us) + " (limit " +
                         milliseconds(options_.fault_timeout_us) + ")");
}

unsigned long long LoadCellReader::transactions() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return transactions_;
}

}  // namespace cdpr::drivers
