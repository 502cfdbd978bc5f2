#include "drivers/can/encoder_unwrap.h"

#include <gtest/gtest.h>

namespace cdpr::drivers::can {
namespace {

constexpr std::uint64_t kRange = 1ull << 25;

TEST(EncoderUnwrap, FirstReadingIsTakenNearestZero) {
  EncoderUnwrap below(kRange), above(kRange);
  ASSERT_EQ(below.add(static_cast<std::uint32_t>(kRange - 5), 100.0), EncoderUnwrap::Outcome::kOk);
  ASSERT_EQ(above.add(5, 100.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(below.counts(), -5);
  EXPECT_EQ(above.counts(), 5);
}

TEST(EncoderUnwrap, FollowsAcrossTheWrapBothWays) {
  // GIVEN an encoder at +3 counts
  EncoderUnwrap e(kRange);
  ASSERT_EQ(e.add(3, 10.0), EncoderUnwrap::Outcome::kOk);
  // WHEN it goes down through zero and back up THEN the count is continuous
  ASSERT_EQ(e.add(static_cast<std::uint32_t>(kRange - 4), 10.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(e.counts(), -4);
  ASSERT_EQ(e.add(static_cast<std::uint32_t>(kRange - 10), 10.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(e.counts(), -10);
  ASSERT_EQ(e.add(2, 20.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(e.counts(), 2);
}

TEST(EncoderUnwrap, FullRangeOf2To32) {
  EncoderUnwrap e(0);
  ASSERT_EQ(e.add(0xFFFFFFFFu, 10.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(e.counts(), -1);
  ASSERT_EQ(e.add(1, 10.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(e.counts(), 1);
}

TEST(EncoderUnwrap, JumpIsRefusedAndLatched) {
  // GIVEN a valid reading
  EncoderUnwrap e(kRange);
  ASSERT_EQ(e.add(1000, 100.0), EncoderUnwrap::Outcome::kOk);
  // WHEN the next one is 1000 counts away but only 100 are possible
  EXPECT_EQ(e.add(2000, 100.0), EncoderUnwrap::Outcome::kJump);
  // THEN it is refused, the position invalid, and stays so
  EXPECT_EQ(e.last_jump_counts(), 1000);
  EXPECT_FALSE(e.valid());
  EXPECT_EQ(e.add(2001, 100.0), EncoderUnwrap::Outcome::kJump);
  // WHEN reset THEN it starts afresh
  e.reset();
  EXPECT_EQ(e.add(2001, 100.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(e.counts(), 2001);
}

TEST(EncoderUnwrap, ValueOutsideTheRangeIsRefused) {
  EncoderUnwrap e(kRange);
  EXPECT_EQ(e.add(static_cast<std::uint32_t>(kRange), 10.0), EncoderUnwrap::Outcome::kOutOfRange);
  EXPECT_FALSE(e.valid());
}

TEST(EncoderUnwrap, FirstReadingIsTakenNearTheCentreTheCallerGives) {
  // GIVEN a 1000-count range and a raw reading past half of it (750)
  EncoderUnwrap unwrap(1000);
  // WHEN no centre is given THEN it is taken nearest zero: -250
  ASSERT_EQ(unwrap.add(750, 10.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(unwrap.counts(), -250);
  // WHEN the payout range says the position lies around 600 (after a restart) THEN 750, then 2750 around 2600
  unwrap.set_centre(600);
  unwrap.reset();
  ASSERT_EQ(unwrap.add(750, 10.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(unwrap.counts(), 750);
  unwrap.set_centre(2600);
  unwrap.reset();
  ASSERT_EQ(unwrap.add(750, 10.0), EncoderUnwrap::Outcome::kOk);
  EXPECT_EQ(unwrap.counts(), 2750);
}

}  // namespace
}  // namespace cdpr::drivers::can
