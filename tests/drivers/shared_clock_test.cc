// The clock a simulator shares with the daemon: what the writer advances,
// a reader in another mapping sees at once; a reader cannot move it, and a
// file that is not a clock is refused with its size.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "drivers/clock/shared_clock.h"

namespace cdpr::drivers {
namespace {

std::string shared_clock_temp_path(const char* name) {
  return ::testing::TempDir() + name + std::to_string(getpid());
}

TEST(SharedClock, AReaderSeesEveryAdvanceOfTheWriter) {
  const std::string path = shared_clock_temp_path("shared_clock_");
  hal::Status status;
  auto writer = SharedClock::create(path, 5'000'000, status);
  ASSERT_TRUE(writer) << status.to_string();
  auto reader = SharedClock::open(path, status);
  ASSERT_TRUE(reader) << status.to_string();
  EXPECT_EQ(reader->now_us(), 5'000'000);
  writer->advance_to(5'020'000);
  EXPECT_EQ(reader->now_us(), 5'020'000);
  writer->advance_to(4'000'000);  // never backwards
  EXPECT_EQ(reader->now_us(), 5'020'000);
  reader->advance_to(9'000'000);  // a reader cannot move it
  EXPECT_EQ(writer->now_us(), 5'020'000);
  std::remove(path.c_str());
}

TEST(SharedClock, AFileThatIsNotAClockIsRefusedWithItsSize) {
  const std::string path = shared_clock_temp_path("not_a_clock_");
  std::ofstream(path) << "hello";
  hal::Status status;
  EXPECT_FALSE(SharedClock::open(path, status));
  EXPECT_NE(status.message().find("5 bytes"), std::string::npos) << status.message();
  EXPECT_FALSE(SharedClock::open(path + ".missing", status));
  EXPECT_EQ(status.code(), hal::ErrorCode::kNotConnected) << status.to_string();
  std::remove(path.c_str());
}

TEST(SharedClock, AnInMemoryClockMovesOnlyForward) {
  auto clock = SharedClock::in_memory(100);
  clock->advance_to(250);
  clock->advance_to(200);
  EXPECT_EQ(clock->now_us(), 250);
}

}  // namespace
}  // namespace cdpr::drivers
