// Buttons: the in-process command button counts presses from any thread; the
// GPIO button (where libgpiod exists) fails clearly without the chip.

#include "drivers/button/command_button.h"

#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "drivers/button/gpio_button.h"

namespace cdpr::drivers::button {
namespace {

TEST(CommandButton, CountsEveryPressFromManyThreadsOnce) {
  // GIVEN a button pressed 4 x 1000 times from 4 threads
  CommandButton button;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&button] {
      for (int i = 0; i < 1000; ++i) button.press();
    });
  }
  for (std::thread& thread : threads) thread.join();
  // WHEN the presses are taken THEN all are counted, and only once
  const hal::Result<int> taken = button.take_presses();
  ASSERT_TRUE(taken.ok());
  EXPECT_EQ(taken.value(), 4000);
  EXPECT_EQ(button.take_presses().value(), 0);
}

#ifdef CDPR_HAVE_GPIOD
TEST(GpioButton, MissingChipIsNotConnectedAndNamed) {
  GpioButtonConfig config;
  config.chip = "/dev/cdpr-no-such-gpiochip";
  const auto button = GpioButton::open(config);
  ASSERT_FALSE(button.ok());
  EXPECT_EQ(button.status().code(), hal::ErrorCode::kNotConnected) << button.status().to_string();
  EXPECT_NE(button.status().message().find("cdpr-no-such-gpiochip"), std::string::npos);
}
#endif

}  // namespace
}  // namespace cdpr::drivers::button
