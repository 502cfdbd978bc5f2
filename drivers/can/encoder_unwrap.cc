#include "drivers/can/encoder_unwrap.h"

#include <cmath>

namespace cdpr::drivers::can {

void EncoderUnwrap::set_range(std::uint64_t range_counts) {
  range_ = range_counts == 0 ? (1ull << 32) : range_counts;
  reset();
}

void EncoderUnwrap::reset() {
  valid_ = false;
  broken_ = false;
  counts_ = 0;
}

std::int64_t EncoderUnwrap::nearest(std::int64_t difference) const {
  // The representative of `difference` modulo the range in [-range/2, range/2).
  const auto range = static_cast<std::int64_t>(range_);
  std::int64_t d = difference % range;
  if (d < 0) d += range;
  if (d >= range - range / 2) d -= range;
  return d;
}

EncoderUnwrap::Outcome EncoderUnwrap::add(std::uint32_t raw, double max_change_counts) {
  if (broken_) return Outcome::kJump;
  if (raw >= range_) return Outcome::kOutOfRange;
  if (!valid_) {
    counts_ = centre_ + nearest(static_cast<std::int64_t>(raw) - centre_);
    last_raw_ = raw;
    valid_ = true;
    return Outcome::kOk;
  }
  const std::int64_t change = nearest(static_cast<std::int64_t>(raw) - static_cast<std::int64_t>(last_raw_));
  if (std::abs(static_cast<double>(change)) > max_change_counts) {
    last_jump_counts_ = change;
    valid_ = false;
    broken_ = true;
    return Outcome::kJump;
  }
  counts_ += change;
  last_raw_ = raw;
  return Outcome::kOk;
}

}  // namespace cdpr::drivers::can
