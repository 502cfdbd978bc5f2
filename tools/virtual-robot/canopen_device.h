#pragma once
// One simulated CANopen device as CiA 301 describes it, strict where real
// devices are: power-on defaults in its object dictionary (heartbeat
// producer off, the device profile's predefined PDOs), so the master must
// configure it; an expedited and segmented SDO server (default SDO
// 0x600/0x580 + node) that refuses what real devices refuse (unknown
// objects, read-only objects, wrong lengths, PDO mapping changes while the
// PDO is valid or the node operational, unmappable objects, more than 64
// bits); NMT with reset node / reset communication back to the defaults and
// a boot-up message; heartbeat producer (0x1017) and consumer (0x1016, the
// monitoring starts with the first heartbeat heard, a timeout is an EMCY
// 0x8130 and the profile's reaction); four RPDOs and four TPDOs per their
// communication and mapping parameters (TPDOs: transmission type 1-240 on
// every n-th SYNC, 254/255 on the event timer and on change of their data,
// a change no sooner than the inhibit time 0x1800:03 after the last frame);
// EMCY (0x80 + node) with the error register 0x1001.
//
// No code shared with the master (drivers/can): the frame type is this
// file's own. Profiles (CiA 402 drive, CiA 406 encoder) derive from it.
// Time: monotonic microseconds passed in. Not thread-safe.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hal/clock.h"
#include "virtual-robot/object_dictionary.h"

namespace cdpr::virtual_robot {

struct BusFrame {
  std::uint32_t id = 0;
  std::uint8_t len = 0;
  std::array<std::uint8_t, 8> data{};
};

enum class NodeState : std::uint8_t { kBootUp = 0x00, kStopped = 0x04, kOperational = 0x05, kPreOperational = 0x7F };

class CanopenDevice {
 public:
  // `od`: the device's objects, power-on values as defaults (check_communication_objects() passed).
  CanopenDevice(int node_id, ObjectDictionary od);
  virtual ~CanopenDevice() = default;
  CanopenDevice(const CanopenDevice&) = delete;
  CanopenDevice& operator=(const CanopenDevice&) = delete;

  int node_id() const { return node_id_; }
  NodeState state() const { return state_; }
  ObjectDictionary& od() { return od_; }
  const ObjectDictionary& od() const { return od_; }

  // A frame from the bus (NMT, SYNC, SDO request, RPDO, others' heartbeats).
  void on_frame(const BusFrame& frame, hal::TimeUs now_us);
  // Appends what is due at now_us: answers, boot-up, heartbeats, TPDOs, EMCY.
  void poll(hal::TimeUs now_us, std::vector<BusFrame>& out);
  // A silent device neither sends nor hears anything (a pulled connector).
  void set_silent(bool silent) { silent_ = silent; }
  bool silent() const { return silent_; }
  // Power cycle: every object to its default, boot-up again.
  void power_on_reset() { reset(false); }
  // Emergency messages sent so far (error codes), for tests.
  const std::vector<std::uint16_t>& emergencies() const { return emergencies_; }
  // Empty when `od` has every communication object this device plays
  // (0x1001, 0x1016:01, 0x1017, and each PDO's parameters), else the first missing.
  static std::string check_communication_objects(const ObjectDictionary& od);
  int rpdo_count() const { return rpdo_count_; }
  int tpdo_count() const { return tpdo_count_; }
  // The longest time between two heartbeats of the producer it consumes
  // (0x1016) as this node heard them: the master's worst gap, plus any
  // delay of the robot's own thread.
  hal::TimeUs longest_consumer_gap_us() const { return longest_consumer_gap_us_; }

 protected:
  // Sends EMCY `code` (0 = error reset) and sets the error register.
  void emergency(std::uint16_t code, std::uint8_t error_register);

  // Profile hooks.
  virtual void on_reset() {}                      // after the dictionary went back to defaults
  virtual void on_rpdo(hal::TimeUs now_us) { (void)now_us; }  // after an RPDO wrote its objects
  virtual void on_heartbeat_lost(int producer) { (void)producer; }
  // A profile's own check of an SDO write (value range, device state): 0 or an abort code.
  virtual std::uint32_t check_write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) {
    (void)index, (void)subindex, (void)value;
    return 0;
  }
  virtual void after_write(std::uint16_t index, std::uint8_t subindex) { (void)index, (void)subindex; }
  // Refresh the objects the TPDOs map (statusword, position) before sending.
  virtual void before_tpdo(hal::TimeUs now_us) { (void)now_us; }

 private:
  struct SdoSession {
    bool active = false;
    std::uint16_t index = 0;
    std::uint8_t subindex = 0;
    std::uint32_t size = 0;
    std::array<std::uint8_t, 8> bytes{};
    std::uint32_t received = 0;
    bool toggle = false;
  };

  void reset(bool communication_only);
  void on_nmt(const BusFrame& frame);
  void on_sdo(const BusFrame& frame);
  void sdo_abort(std::uint16_t index, std::uint8_t subindex, std::uint32_t code);
  void sdo_reply(std::uint8_t command, std::uint16_t index, std::uint8_t subindex, std::uint32_t value);
  std::uint32_t write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value, std::uint32_t size);
  std::uint32_t check_pdo_write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) const;
  void on_rpdo_frame(int pdo, const BusFrame& frame, hal::TimeUs now_us);
  void on_heartbeat_frame(int producer, hal::TimeUs now_us);
  void check_consumers(hal::TimeUs now_us);
  void send_tpdos(hal::TimeUs now_us, bool sync);
  bool tpdo_data(int pdo, BusFrame& frame) const;
  void queue(std::uint32_t id, std::initializer_list<std::uint8_t> bytes);

  int node_id_;
  ObjectDictionary od_;
  int rpdo_count_ = 0;  // 0..4: the PDOs the dictionary has
  int tpdo_count_ = 0;
  NodeState state_ = NodeState::kPreOperational;
  bool boot_up_pending_ = true;
  bool silent_ = false;
  SdoSession sdo_;
  std::vector<BusFrame> outbox_;
  hal::TimeUs next_heartbeat_us_ = -1;
  std::array<hal::TimeUs, 4> tpdo_next_event_us_{-1, -1, -1, -1};
  std::array<BusFrame, 4> tpdo_last_{};
  std::array<bool, 4> tpdo_sent_{};
  std::array<hal::TimeUs, 4> tpdo_last_us_{};
  int sync_count_ = 0;
  bool sync_pending_ = false;
  hal::TimeUs consumer_last_us_ = -1;  // last heartbeat of the 0x1016:01 producer; -1: not armed
  hal::TimeUs longest_consumer_gap_us_ = 0;
  std::vector<std::uint16_t> emergencies_;
};

}  // namespace cdpr::virtual_robot
