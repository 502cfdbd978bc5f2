#include "drivers/can/drain_frames.h"

#include <gtest/gtest.h>

#include <deque>
#include <vector>

namespace cdpr::drivers::can {
namespace {

// One receive() of the script: a frame with this id, or this error.
struct Step {
  std::uint32_t id = 0;
  hal::ErrorCode error = hal::ErrorCode::kOk;
};
Step frame(std::uint32_t id) { return {id, hal::ErrorCode::kOk}; }
Step failure(hal::ErrorCode error) { return {0, error}; }

// A bus whose receive() plays back a script, then finds nothing.
class ScriptedTransport : public CanTransport {
 public:
  explicit ScriptedTransport(std::initializer_list<Step> script) : script_(script) {}
  hal::Status send(const CanFrame&) override { return hal::Status::Ok(); }
  hal::Result<bool> receive(CanFrame& out, hal::TimeUs timeout_us) override {
    EXPECT_EQ(timeout_us, 0) << "an update must never wait for the bus";
    ++receives;
    if (script_.empty()) return false;
    const Step next = script_.front();
    script_.pop_front();
    if (next.error != hal::ErrorCode::kOk) return hal::Status(next.error, "scripted");
    out = CanFrame{};
    out.id = next.id;
    return true;
  }
  int receives = 0;

 private:
  std::deque<Step> script_;
};

// What one drain handed on, returned and counted.
struct Drained {
  std::vector<std::uint32_t> ids;
  hal::Status status;
};
Drained drain(ScriptedTransport& bus, int max_frames, hal::WinchBankCounters& counters) {
  Drained d;
  d.status = drain_frames(bus, max_frames, counters, [&](const CanFrame& f) { d.ids.push_back(f.id); });
  return d;
}
using Ids = std::vector<std::uint32_t>;

TEST(DrainFrames, HandsOnEveryQueuedFrameInOrderAndStopsWhenTheBusIsEmpty) {
  // GIVEN three frames queued
  ScriptedTransport bus({frame(0x181), frame(0x701), frame(0x182)});
  hal::WinchBankCounters counters;
  // WHEN drained with room for more THEN each is handled once, in order, and counted
  const Drained d = drain(bus, 10, counters);
  EXPECT_EQ(d.ids, (Ids{0x181, 0x701, 0x182}));
  EXPECT_TRUE(d.status.ok());
  EXPECT_EQ(counters.frames_rx, 3u);
  EXPECT_EQ(counters.errors, 0u);
  EXPECT_EQ(bus.receives, 4);  // the fourth found the bus empty
}

TEST(DrainFrames, TakesAtMostOneUpdatesShareAndLeavesTheRestQueued) {
  // GIVEN a flooded bus
  ScriptedTransport bus({frame(1), frame(2), frame(3), frame(4), frame(5)});
  hal::WinchBankCounters counters;
  // WHEN drained with a share of 2 THEN two frames are handled, the next call gets the next two
  EXPECT_EQ(drain(bus, 2, counters).ids, (Ids{1, 2}));
  EXPECT_EQ(drain(bus, 2, counters).ids, (Ids{3, 4}));
  EXPECT_EQ(counters.frames_rx, 4u);
}

TEST(DrainFrames, SkipsAMalformedRecordCountingItAsAnError) {
  // GIVEN a malformed record between two frames
  ScriptedTransport bus({frame(0x181), failure(hal::ErrorCode::kCorruptData), frame(0x182)});
  hal::WinchBankCounters counters;
  // WHEN drained THEN both frames are handled, the record counted, the update goes on
  const Drained d = drain(bus, 10, counters);
  EXPECT_EQ(d.ids, (Ids{0x181, 0x182}));
  EXPECT_TRUE(d.status.ok());
  EXPECT_EQ(counters.errors, 1u);
  EXPECT_EQ(counters.frames_rx, 2u);
}

TEST(DrainFrames, ReturnsAnyOtherTransportErrorAfterHandlingTheFramesBeforeIt) {
  // GIVEN the peer closing after one frame
  ScriptedTransport bus({frame(0x181), failure(hal::ErrorCode::kNotConnected), frame(0x182)});
  hal::WinchBankCounters counters;
  // WHEN drained THEN the first frame is handled and the error returned, nothing after it read
  const Drained d = drain(bus, 10, counters);
  EXPECT_EQ(d.ids, (Ids{0x181}));
  EXPECT_EQ(d.status.code(), hal::ErrorCode::kNotConnected);
  EXPECT_EQ(counters.errors, 1u);
  EXPECT_EQ(bus.receives, 2);
}

}  // namespace
}  // namespace cdpr::drivers::can
