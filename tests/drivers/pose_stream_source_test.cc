// Loopback: the pose stream source reading from the far end of a real Unix
// socket pair, with malformed lines interleaved.

#include "drivers/pose/pose_stream_source.h"

#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <string>

#include <gtest/gtest.h>

#include "../fakes/manual_clock.h"

namespace cdpr::drivers::pose {
namespace {

class PoseStreamSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    int fds[2];
    ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
    peer_ = fds[1];
    const int ours = fds[0];
    source_ = std::make_unique<PoseStreamSource>([ours]() -> hal::Result<int> { return ours; }, "test", clock_);
    ASSERT_TRUE(source_->open().ok());
  }
  void TearDown() override {
    if (peer_ >= 0) ::close(peer_);
  }
  void send(const std::string& bytes) {
    ASSERT_EQ(::write(peer_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  }

  fakes::ManualClock clock_{1'000'000};
  int peer_ = -1;
  std::unique_ptr<PoseStreamSource> source_;
};

TEST_F(PoseStreamSourceTest, KeepsTheLatestGoodSampleAndCountsMalformedLines) {
  // GIVEN good lines with garbage between them, the last good one split in two writes
  send("POSE 1 1 1 1 1 0 0 0 1\n");
  send("garbage\nPOSE 2 nan 0 0 1 0 0 0 1\n\n# comment\n");
  send(std::string("\x00\xff\x01\n", 4));
  send("POSE 3 3.5 2 1 1 0 ");
  clock_.advance_ms(5);
  // WHEN updated
  ASSERT_TRUE(source_->update(100'000).ok());
  // THEN the first line is the latest (the third is incomplete), 3 lines rejected
  ASSERT_TRUE(source_->latest().has_value());
  EXPECT_EQ(source_->latest()->source_time_us, 1);
  EXPECT_EQ(source_->counters().samples, 1u);
  EXPECT_EQ(source_->counters().rejected_lines, 3u);
  // WHEN the rest of the split line arrives
  send("0 0 1\n");
  clock_.advance_ms(5);
  ASSERT_TRUE(source_->update(100'000).ok());
  // THEN it is the latest, stamped with the clock at its arrival
  EXPECT_EQ(source_->latest()->source_time_us, 3);
  EXPECT_DOUBLE_EQ(source_->latest()->platform_world.x, 3.5);
  EXPECT_EQ(source_->latest()->received_us, 1'010'000);
  EXPECT_EQ(source_->counters().samples, 2u);
}

TEST_F(PoseStreamSourceTest, DropsAnOverLongLineOnceAndResynchronises) {
  // GIVEN a 1000-byte line followed by a good one
  send(std::string(1000, 'x') + "\nPOSE 9 0 0 0 1 0 0 0 0\n");
  // WHEN updated (maybe in more than one call)
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(source_->update(50'000).ok());
  // THEN the long line counts once, the good one is read
  EXPECT_EQ(source_->counters().rejected_lines, 1u);
  EXPECT_EQ(source_->last_rejection(), PoseLineResult::kTooLong);
  ASSERT_TRUE(source_->latest().has_value());
  EXPECT_EQ(source_->latest()->source_time_us, 9);
  EXPECT_FALSE(source_->latest()->valid);
}

TEST_F(PoseStreamSourceTest, WaitsNoLongerThanItsTimeout) {
  // GIVEN a silent stream WHEN updated with 30 ms timeout
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(source_->update(30'000).ok());
  const auto elapsed = std::chrono::steady_clock::now() - start;
  // THEN it returned ok with nothing, after about 30 ms
  EXPECT_FALSE(source_->latest().has_value());
  EXPECT_GE(elapsed, std::chrono::milliseconds(25));
  EXPECT_LT(elapsed, std::chrono::milliseconds(500));
}

TEST_F(PoseStreamSourceTest, PeerClosingIsNotConnectedAndKeepsTheLastSample) {
  send("POSE 5 0 0 0 1 0 0 0 1\n");
  ::close(peer_);
  peer_ = -1;
  hal::Status status = source_->update(100'000);
  // The sample and the close may come in one update or two.
  if (status.ok()) status = source_->update(100'000);
  EXPECT_EQ(status.code(), hal::ErrorCode::kNotConnected) << status.to_string();
  ASSERT_TRUE(source_->latest().has_value());
  EXPECT_EQ(source_->latest()->source_time_us, 5);
  EXPECT_EQ(source_->update(0).code(), hal::ErrorCode::kInvalidState);
}

TEST(PoseStreamSourceEndpoint, UnknownSchemeAndMissingSocketFailClearly) {
  fakes::ManualClock clock;
  PoseStreamSource bad("udp:1.2.3.4:5", clock);
  EXPECT_EQ(bad.open().code(), hal::ErrorCode::kInvalidArgument);
  PoseStreamSource missing("unix:/tmp/cdpr-no-such-dir/pose.sock", clock);
  const hal::Status status = missing.open();
  EXPECT_EQ(status.code(), hal::ErrorCode::kNotConnected);
  EXPECT_NE(status.message().find("pose.sock"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace cdpr::drivers::pose
