#pragma once
// A simulated CiA 402 drive (profile position mode) on a CanopenDevice,
// from the standard's tables and written independently of the master:
//
// - power state machine of the controlword (0x6040) and statusword (0x6041)
//   coding, transitions 2-16 (3 and 4 together on "enable operation");
// - modes of operation 0x6060 / display 0x6061: profile position (1) and
//   homing (6); power-on mode configurable (drives that cannot store
//   profile position come up in homing); in homing, bit 4 starts homing
//   (the position is re-zeroed at once, homing attained shows in bit 12),
//   in any mode but profile position, bit 4 does not take a target;
// - profile position: a rising edge of bit 4 takes 0x607A (absolute; bit 6
//   relative) at once with bit 5 or when idle, else after the running move;
//   set-point acknowledge (bit 12) shows one PDO cycle later and clears one
//   cycle after bit 4 is seen low; while it is set (handshake not finished)
//   a rising edge of bit 4 is ignored, as CiA 402 allows; trapezoidal moves with 0x6081 / 0x6083 /
//   0x6084 inside the software limits 0x607D; halt (bit 8) decelerates with
//   0x6084 and holds; target reached bit 10;
// - quick stop per 0x605A (0: stop at once, 1/2: slow-down / quick-stop
//   ramp then switch on disabled, 5/6: the same ramps staying in quick stop
//   active), quick-stop deceleration 0x6085;
// - following error: when the motor cannot follow the demand (capped at
//   motor_max_speed) by more than 0x6065, a fault with EMCY 0x8611 and
//   0x603F; fault reaction on the quick-stop ramp;
// - heartbeat consumer loss: reaction per 0x6007 (1 fault, 2 disable
//   voltage, 3 quick stop), EMCY 0x8130 from CanopenDevice;
// - velocity units as its 0x60A9 says: position increments per second
//   when the EDS has no 0x60A9 (the factor group at its CiA 402 default of
//   1), or rpm (0x00B44700) as maxon EPOS4, Nanotec and Synapticon drives
//   come: profile velocity 0x6081 in rpm, 0x6083/0x6084/0x6085 in rpm/s,
//   max motor speed 0x6080 in rpm (a faster 0x6081 is refused), and
//   counts_per_rev motor position counts per revolution; a velocity
//   factor 0x6096 and an acceleration factor 0x6097 where its EDS has them
//   (internal = written x numerator / divisor);
// Its objects, their power-on values (the shipped cdpr-virtual-drive.eds:
// the CiA 402 predefined PDOs, RPDO1 = controlword only, TPDO1 = statusword
// only, the others invalid), PDO count and ranges come from its EDS.
// Units: position counts, time simulated seconds in advance(). Not
// thread-safe.

#include <cstdint>

#include <string>

#include "virtual-robot/canopen_device.h"
#include "virtual-robot/object_dictionary_eds.h"

namespace cdpr::virtual_robot {

struct DriveDefaults {
  DeviceEds eds = shipped_eds("cdpr-virtual-drive.eds");
  StoredParameters stored;                   // e.g. 0x6060 = 6: a drive that comes up in homing
  double motor_max_speed = 1e9;              // what the motor can do [counts/s]
  double ack_delay_s = 0.010;                // one PDO cycle [s, real time]
  double counts_per_rev = 4096.0;            // motor position counts per revolution (for rpm)
};

class Cia402Device final : public CanopenDevice {
 public:
  // Aborts when check() refuses `defaults`: check files from outside first.
  Cia402Device(int node_id, const DriveDefaults& defaults);
  // Empty when the drive can play `defaults.eds`, else why not ("<file>: no
  // object 0x6041:00 (statusword), which the drive plays").
  static std::string check(int node_id, const DriveDefaults& defaults);

  // Moves the axis by dt_s of simulated time.
  void advance(double dt_s);
  double position_counts() const { return actual_; }
  // Where the axis is at power on [counts] (the winch's position counter).
  void set_initial_position(double counts) { actual_ = demand_ = target_ = counts; }
  // No profile running and the motor still.
  bool at_rest() const { return velocity_ == 0.0 && !moving_ && demand_ == actual_; }
  // The motor still (velocity 0 and where the profile wants it), also while halted mid-move.
  bool axis_still() const { return velocity_ == 0.0 && demand_ == actual_; }
  // Braking to rest on a stop (quick stop, fault reaction, or halt bit 8) and still moving.
  bool braking() const;
  // The axis held still (brake, blocked winch) or released: for following errors.
  void set_blocked(bool blocked) { blocked_ = blocked; }
  // For tests and the robot: where the drive is heading, and its power state name.
  double demand_counts() const { return demand_; }
  bool operation_enabled() const;
  std::uint16_t statusword() const { return static_cast<std::uint16_t>(od().get(0x6041, 0)); }

 private:
  enum class Power { kSwitchOnDisabled, kReadyToSwitchOn, kSwitchedOn, kOperationEnabled, kQuickStopActive,
                     kFaultReaction, kFault };

  void on_reset() override;
  void on_rpdo(hal::TimeUs now_us) override;
  void on_heartbeat_lost(int producer) override;
  std::uint32_t check_write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) override;
  void after_write(std::uint16_t index, std::uint8_t subindex) override;
  void before_tpdo(hal::TimeUs now_us) override;

  void apply_controlword(std::uint16_t controlword, hal::TimeUs now_us);
  void start_quick_stop();
  void fault(std::uint16_t code);
  void take_setpoint(hal::TimeUs now_us);
  // Decelerates to rest with `deceleration` [counts/s^2]; true when at rest.
  bool brake(double deceleration, double dt_s);
  void move_towards_target(double dt_s);
  std::uint16_t compose_statusword() const;
  // 0x6081 [counts/s] or 0x6083/0x6084/0x6085 [counts/s^2] as the motion uses them.
  double counts_per_s(std::uint16_t index) const;

  DriveDefaults defaults_;
  bool rpm_units_ = false;  // 0x60A9 = rpm
  Power power_ = Power::kSwitchOnDisabled;
  std::uint16_t last_controlword_ = 0;
  double demand_ = 0.0;     // profile generator position [counts]
  double velocity_ = 0.0;   // profile generator velocity [counts/s]
  double actual_ = 0.0;     // motor position [counts]
  double target_ = 0.0;
  bool has_buffered_ = false;
  double buffered_target_ = 0.0;
  bool moving_ = false;
  bool ack_ = false;               // set-point acknowledge as the statusword shows it
  bool setpoint_busy_ = false;     // a set-point taken, handshake not finished: edges are ignored
  hal::TimeUs ack_set_us_ = -1;    // when the acknowledgement shows
  hal::TimeUs ack_clear_us_ = -1;  // when it clears (bit 4 seen low)
  bool homing_attained_ = false;
  bool blocked_ = false;
  bool disable_after_stop_ = false;
  hal::TimeUs now_us_ = 0;
};

}  // namespace cdpr::virtual_robot
