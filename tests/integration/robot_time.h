#pragma once
// Waiting in the virtual robot's time (virtual-robot/virtual_robot.h
// "Time"): a test gives a run the robot time it needs, so a robot starved
// of CPU, which runs slower, gets the same simulated time to do the same
// work, and what a test measures of a stop (how long, how far) is measured
// in the time the daemon and the drives count. Only ctest's time limit of
// the test's kind bounds the wall-clock time.

#include <chrono>
#include <thread>

#include "hal/clock.h"

namespace cdpr::integration {

class RobotDeadline {
 public:
  RobotDeadline(const hal::Clock& robot_clock, std::chrono::microseconds span)
      : clock_(robot_clock), until_us_(robot_clock.now_us() + span.count()) {}
  bool passed() const { return clock_.now_us() >= until_us_; }
  void wait() const {
    while (!passed()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }

 private:
  const hal::Clock& clock_;
  hal::TimeUs until_us_;
};

// Polls `ready` every 20 ms for up to `timeout` of the robot's time.
template <class Predicate>
bool wait_until_robot(const hal::Clock& robot_clock, Predicate ready, std::chrono::milliseconds timeout) {
  const RobotDeadline deadline(robot_clock, timeout);
  while (!ready()) {
    if (deadline.passed()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

// Milliseconds of the robot's time since `start_us` on its clock.
inline double robot_ms_since(const hal::Clock& robot_clock, hal::TimeUs start_us) {
  return 1e-3 * static_cast<double>(robot_clock.now_us() - start_us);
}

}  // namespace cdpr::integration
