#pragma once
// A hal::LoadCell whose read() never waits for the bus: a thread of its own
// owns a blocking hal::LoadCell (the Modbus driver), opens it, reads it every
// poll_interval_us and publishes the latest outcome; read() only looks at
// what was published. So a silent, slow or garbage-talking transmitter costs
// the control loop a mutex and a copy, never a response timeout.
//
// read() returns at once:
//   - the latest good reading while it is at most fault_timeout_us old
//     (time_us says when it arrived; the same reading comes back until a
//     newer one does: compare time_us to tell);
//   - kDeviceFault as soon as the transmitter's last answer reports an error
//     (its status flag or a non-finite value): a measured fault, not a late one;
//   - otherwise the last failure (timeout, CRC, exception, connection lost)
//     with how long nothing good came, once the last good reading (or open())
//     is more than fault_timeout_us ago; before that, while no reading has
//     come yet, kTimeout "no reading yet".
// So a transmitter that falls silent is reported within fault_timeout_us
// plus one transaction of the inner driver.
//
// open() starts the thread and returns (the inner open() and its reconnects
// happen there, every reconnect_interval_us while they fail); close() stops
// it, waiting for the inner driver's transaction in flight (at most its
// response timeout x tries). The inner driver is used by the thread only,
// between open() and close(); it must outlive this object, and its clock
// must be safe to read from another thread (the monotonic clock is).
// read(), open() and close() from one thread.

#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "hal/clock.h"
#include "hal/load_cell.h"

namespace cdpr::drivers {

struct LoadCellReaderOptions {
  hal::TimeUs poll_interval_us = 20'000;       // from the start of one read to the next
  hal::TimeUs fault_timeout_us = 1'000'000;    // no good reading for this long is a fault
  hal::TimeUs reconnect_interval_us = 1'000'000;
};

class LoadCellReader final : public hal::LoadCell {
 public:
  // `clock` (the loop's) judges ages; it must be the inner driver's clock too.
  LoadCellReader(hal::LoadCell& inner, const hal::Clock& clock, LoadCellReaderOptions options);
  ~LoadCellReader() override;
  LoadCellReader(const LoadCellReader&) = delete;
  LoadCellReader& operator=(const LoadCellReader&) = delete;

  hal::Status open() override;
  void close() override;
  hal::Result<hal::TensionSample> read() override;

  // Transactions the thread has completed (diagnostics and tests).
  unsigned long long transactions() const;

 private:
  void run();
  // Waits until `deadline_us` or close(); false when closing.
  bool sleep_until(hal::TimeUs deadline_us);

  hal::LoadCell& inner_;
  const hal::Clock& clock_;
  LoadCellReaderOptions options_;
  std::thread thread_;

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  bool stopping_ = false;
  hal::TimeUs opened_us_ = 0;
  std::optional<hal::TensionSample> latest_;
  hal::Status last_failure_;       // of the latest transaction; ok when it succeeded
  hal::TimeUs last_failure_us_ = 0;
  unsigned long long transactions_ = 0;
};

}  // namespace cdpr::drivers
