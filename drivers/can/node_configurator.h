#pragma once
// Configure-and-verify of one CANopen node over SDO: a list of steps
// (write, write and read back, read and compare, read and keep) run one
// after the other through an SdoClient, non-blocking, driven by the owner's
// update() with the frames it receives. The first mismatch or refusal ends
// the run with a message that names the node, the object and the values
// ("node 3: 0x1A00:01 (TPDO1 mapping 1) reads 0x60410010, wrote 0x60640020").
// Steps are built once per node (device_configuration.h); running them
// allocates nothing but the error text.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/can/sdo_client.h"

namespace cdpr::drivers::can {

struct SdoStep {
  enum class Kind { kWrite, kWriteVerify, kExpect, kRead };
  Kind kind = Kind::kWrite;
  std::uint16_t index = 0;
  std::uint8_t subindex = 0;
  std::uint8_t size = 4;     // bytes of the object: 1, 2 or 4
  std::uint32_t value = 0;   // written, or expected
  const char* what = "";     // the object's name for messages
  // The device may not have the object (an unused PDO of a device with
  // fewer, an optional profile object): abort 0x06020000 or 0x06090011
  // skips the step (a kRead then has no value) instead of failing the run.
  bool optional = false;
  // The bits a read back (kWriteVerify) or kExpect compares: a device may
  // keep a bit at its own value (COB-ID bit 30, "no RTR").
  std::uint32_t compare_mask = 0xFFFFFFFFu;
  // A write refused with any other abort is tried once more with this
  // value (transmission type 254 where 255 is refused); 0: none.
  std::uint32_t fallback = 0;
  bool has_fallback = false;
};

class NodeConfigurator {
 public:
  enum class State { kIdle, kRunning, kDone, kFailed, kNoAnswer };

  NodeConfigurator(int node_id, hal::TimeUs sdo_timeout_us) : node_id_(node_id), sdo_(node_id, sdo_timeout_us) {}

  // Runs `steps` from the first; `steps` must outlive the run.
  void start(const std::vector<SdoStep>* steps);
  void cancel();
  // A received frame; true when it was this node's SDO response.
  bool on_frame(const CanFrame& frame, hal::TimeUs now_us) { return sdo_.on_frame(frame, now_us); }
  // Advances the run; the frame to send now, if any.
  std::optional<CanFrame> poll(hal::TimeUs now_us);

  State state() const { return state_; }
  // Whether the present (or last) run is of `steps`: the node's one SDO
  // channel is shared by configuration, mode check, move profiles and
  // fault diagnosis, one after the other.
  bool runs(const std::vector<SdoStep>* steps) const { return steps_ == steps; }
  // Why the run failed (kFailed: a refusal or mismatch; kNoAnswer: timeout).
  const std::string& error() const { return error_; }
  // The value a kRead step read (index:subindex), if it ran.
  std::optional<std::uint32_t> read_value(std::uint16_t index, std::uint8_t subindex) const;

 private:
  void fail(State state, const std::string& why);
  void next_step();
  std::string name(const SdoStep& step) const;

  int node_id_;
  SdoClient sdo_;
  const std::vector<SdoStep>* steps_ = nullptr;
  std::size_t next_ = 0;
  bool reading_back_ = false;
  std::uint32_t written_ = 0;  // what the present step wrote (its value or its fallback)
  bool fell_back_ = false;
  State state_ = State::kIdle;
  std::string error_;
  std::vector<std::uint32_t> read_values_;  // per step; sized at start()
  std::vector<bool> read_done_;
};

}  // namespace cdpr::drivers::can
