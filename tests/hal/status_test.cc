#include "hal/status.h"

#include <string>

#include <gtest/gtest.h>

// Every hal header must compile on its own and together.
#include "hal/button.h"
#include "hal/clock.h"
#include "hal/geometry.h"
#include "hal/load_cell.h"
#include "hal/pose_source.h"
#include "hal/winch_bank.h"

namespace cdpr::hal {
namespace {

TEST(Status, DefaultIsOkWithEmptyMessage) {
  // GIVEN / WHEN a default status
  const Status status;
  // THEN it is ok and says so
  EXPECT_TRUE(status.ok());
  EXPECT_EQ(status.code(), ErrorCode::kOk);
  EXPECT_TRUE(status.message().empty());
  EXPECT_EQ(status.to_string(), "ok");
}

TEST(Status, ErrorCarriesCodeAndMessage) {
  // GIVEN an error built by a driver
  const Status status(ErrorCode::kTimeout, "load cell: no reply after 3 tries");
  // THEN code and message survive and to_string() names both
  EXPECT_FALSE(status.ok());
  EXPECT_EQ(status.code(), ErrorCode::kTimeout);
  EXPECT_EQ(status.to_string(), "timeout: load cell: no reply after 3 tries");
}

TEST(Status, EveryCodeHasADistinctName) {
  // GIVEN all codes
  const ErrorCode codes[] = {ErrorCode::kOk,          ErrorCode::kTimeout,       ErrorCode::kNotConnected,
                             ErrorCode::kIoError,     ErrorCode::kCorruptData,   ErrorCode::kProtocolError,
                             ErrorCode::kDeviceFault, ErrorCode::kNodeDead,      ErrorCode::kInvalidArgument,
                             ErrorCode::kInvalidState, ErrorCode::kUnsupported};
  // THEN their names differ pairwise and none is "unknown"
  for (ErrorCode a : codes) {
    EXPECT_STRNE(to_string(a), "unknown");
    for (ErrorCode b : codes) {
      if (a != b) {
        EXPECT_STRNE(to_string(a), to_string(b));
      }
    }
  }
}

TEST(Result, HoldsValueOrStatus) {
  // GIVEN a result with a value and one with an error
  const Result<TensionSample> good(TensionSample{812.5, true, 42});
  const Result<TensionSample> bad(Status(ErrorCode::kCorruptData, "bad CRC"));
  // THEN the first is ok with its value, the second carries its error
  ASSERT_TRUE(good.ok());
  EXPECT_DOUBLE_EQ(good.value().tension_n, 812.5);
  EXPECT_TRUE(good.value().stable);
  EXPECT_EQ(good.value().time_us, 42);
  EXPECT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), ErrorCode::kCorruptData);
  EXPECT_EQ(bad.status().message(), "bad CRC");
}

TEST(Result, FromAnOkStatusIsAnErrorNotAnEmptyValue) {
  // GIVEN a result built (by mistake) from an ok status
  const Result<int> result{Status::Ok()};
  // THEN it does not claim a value
  EXPECT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), ErrorCode::kInvalidState);
}

TEST(DriveState, NamesAreDistinct) {
  EXPECT_STRNE(to_string(DriveState::kEnabled), to_string(DriveState::kDisabled));
  EXPECT_STRNE(to_string(DriveState::kFault), to_string(DriveState::kQuickStop));
}

}  // namespace
}  // namespace cdpr::hal
