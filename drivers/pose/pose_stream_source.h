#pragma once
// hal::PoseSource reading the line protocol of drivers/pose/pose_line.h from
// a Unix or TCP stream socket (the localization system or the virtual robot
// serves it; we connect).
//
// update() drains what has arrived (at most kMaxReadsPerUpdate reads, so a
// flood cannot starve the loop) into a fixed line buffer, parses each
// complete line, stamps accepted samples with the injected clock and keeps
// the latest. Malformed and over-long lines are counted and dropped, never
// an error; a peer that closes gives kNotConnected (call open() to
// reconnect). No allocation after open(). One thread at a time.
//
// With an endpoint, open() only starts the connect and update() finishes it
// (kNotConnected when it fails or takes longer than connect_timeout_us), so
// neither waits for a slow or unreachable peer. A TCP host name is resolved
// in open() (use a numeric address where DNS could stall).

#include <array>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "drivers/pose/pose_line.h"
#include "hal/clock.h"
#include "hal/pose_source.h"

namespace cdpr::drivers::pose {

// Returns a connected stream fd (the source takes ownership).
using FdConnector = std::function<hal::Result<int>()>;

class PoseStreamSource final : public hal::PoseSource {
 public:
  static constexpr int kMaxReadsPerUpdate = 64;

  // `endpoint`: "unix:<path>" or "tcp:<host>:<port>"; a connect not done
  // within connect_timeout_us fails. `clock` must outlive this object.
  PoseStreamSource(const std::string& endpoint, const hal::Clock& clock, hal::TimeUs connect_timeout_us = 1'000'000);
  // Any way to get a connected fd (tests: one end of a socketpair).
  PoseStreamSource(FdConnector connector, std::string name, const hal::Clock& clock);
  ~PoseStreamSource() override;
  PoseStreamSource(const PoseStreamSource&) = delete;
  PoseStreamSource& operator=(const PoseStreamSource&) = delete;

  hal::Status open() override;
  void close() override;
  hal::Status update(hal::TimeUs timeout_us) override;
  std::optional<hal::PoseSample> latest() const override { return latest_; }
  hal::PoseSourceCounters counters() const override { return counters_; }
  // Why the last line was rejected (kSample when none was), for diagnostics.
  PoseLineResult last_rejection() const { return last_rejection_; }

 private:
  void consume_lines(hal::TimeUs now_us);
  // Finishes a connect in progress: Ok when connected or still within its
  // time (connecting_ tells), else the failure (the fd closed).
  hal::Status finish_connect();
  void handle_line(std::string_view line, hal::TimeUs now_us);

  FdConnector connector_;  // empty: connect to endpoint_ without waiting
  std::string endpoint_;
  hal::TimeUs connect_timeout_us_ = 0;
  bool connecting_ = false;
  hal::TimeUs connect_started_us_ = 0;
  std::string name_;
  const hal::Clock& clock_;
  int fd_ = -1;
  std::array<char, kMaxPoseLineBytes> buffer_{};
  std::size_t fill_ = 0;
  bool discarding_ = false;  // inside an over-long line: drop up to its '\n'
  std::optional<hal::PoseSample> latest_;
  hal::PoseSourceCounters counters_;
  PoseLineResult last_rejection_ = PoseLineResult::kSample;
};

}  // namespace cdpr::drivers::pose
