// Fuzz target: the pose stream (drivers/pose/pose_stream_source.h and
// pose_line.h), the localization system's line protocol as the daemon reads
// it: bytes arrive on a real socket in pieces, are cut into lines in a fixed
// buffer and parsed. Promises checked: never a crash; the latest accepted
// sample is finite with a unit quaternion; every line is counted once as a
// sample, a rejection or a comment, never more lines than newlines + 1.
// The first byte picks the size of the pieces written to the socket.

#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../fakes/manual_clock.h"
#include "drivers/pose/pose_stream_source.h"
#include "fuzz_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace cdpr::drivers::pose;
  using cdpr::fuzz::require;
  if (size == 0) return 0;
  const std::size_t piece = 1 + data[0];
  data += 1;
  size -= 1;
  int fds[2];
  require(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds) == 0, "socketpair");
  cdpr::fakes::ManualClock clock(1'000'000);
  const int source_end = fds[0];
  PoseStreamSource source([source_end]() -> cdpr::hal::Result<int> { return source_end; }, "fuzz pose stream", clock);
  require(source.open().ok(), "open on a socketpair");
  for (std::size_t at = 0; at < size; at += piece) {
    const std::size_t n = size - at < piece ? size - at : piece;
    require(::write(fds[1], data + at, n) == static_cast<ssize_t>(n), "write to the socketpair");
    clock.advance_us(1000);
    require(source.update(0).ok(), "an open stream with data never fails");
  }
  ::close(fds[1]);
  (void)source.update(0);  // sees the end of the stream
  std::size_t newlines = 0;
  for (std::size_t i = 0; i < size; ++i) newlines += data[i] == '\n';
  const auto counters = source.counters();
  require(counters.samples + counters.rejected_lines <= newlines + 1, "each line counted at most once");
  if (const auto latest = source.latest()) {
    const auto& p = latest->platform_world;
    const auto& q = latest->world_R_platform;
    require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z), "accepted positions are finite");
    require(std::abs(std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z) - 1.0) <= 1e-9,
            "accepted quaternions are unit");
    require(latest->received_us > 0, "accepted samples are stamped with the clock");
  }
  return 0;
}
