#pragma once
// CiA 406 position value (0x6004) to a continuous count. The encoder reports
// an UNSIGNED32 that wraps at its total measuring range (0x6002): a payout a
// few counts below the encoder's zero reads as range - a few. The first
// reading is taken nearest the centre (in [centre - range/2, centre +
// range/2); the centre is 0 unless the caller knows where the payout range
// lies, so a raw position past half the range after a restart is not taken
// a whole range off); every later one is
// unwrapped as the shortest way round from the previous reading. A change
// larger than the caller says is physically possible since the previous
// reading is a jump: the reading is refused and the unwrapper stays invalid
// until reset(), so a corrupted or re-zeroed encoder never becomes a move.
// Pure logic, no I/O, no allocation.

#include <cstdint>

namespace cdpr::drivers::can {

class EncoderUnwrap {
 public:
  // range_counts: positions 0 .. range - 1; 0 means the full 2^32.
  EncoderUnwrap() = default;
  explicit EncoderUnwrap(std::uint64_t range_counts) { set_range(range_counts); }

  void set_range(std::uint64_t range_counts);
  std::uint64_t range() const { return range_; }
  // Where the first reading after a reset is taken nearest [counts]; kept across reset().
  void set_centre(std::int64_t centre_counts) { centre_ = centre_counts; }
  // Forgets the history (node rebooted, range changed, fault acknowledged).
  void reset();

  // The most a payout of at most max_speed_mps may change [counts] between
  // the previous reading (at previous_us; < 0: none) and one at now_us.
  // Readings queued together arrive with one receive time: the change of
  // `allowance_us` is allowed on top of the time between them.
  static double max_change_counts(double max_speed_mps, std::int64_t previous_us, std::int64_t now_us,
                                  std::int64_t allowance_us, double m_per_count) {
    const std::int64_t since_us = previous_us < 0 ? 0 : now_us - previous_us;
    return max_speed_mps * 1e-6 * static_cast<double>(since_us + allowance_us) / m_per_count;
  }

  enum class Outcome { kOk, kOutOfRange, kJump };
  // One reading; max_change_counts bounds |change| since the previous one.
  Outcome add(std::uint32_t raw, double max_change_counts);

  bool valid() const { return valid_; }
  std::int64_t counts() const { return counts_; }
  // The refused change of the last kJump [counts].
  std::int64_t last_jump_counts() const { return last_jump_counts_; }

 private:
  std::int64_t nearest(std::int64_t difference) const;

  std::uint64_t range_ = 1ull << 32;
  std::int64_t centre_ = 0;
  bool valid_ = false;
  bool broken_ = false;
  std::uint32_t last_raw_ = 0;
  std::int64_t counts_ = 0;
  std::int64_t last_jump_counts_ = 0;
};

}  // namespace cdpr::drivers::can
