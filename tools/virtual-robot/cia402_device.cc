#include "virtual-robot/cia402_device.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace cdpr::virtual_robot {
namespace {

constexpr std::uint16_t kEmcyFollowingError = 0x8611;
constexpr std::uint16_t kEmcyHeartbeat = 0x8130;
constexpr std::int8_t kModeProfilePosition = 1;
constexpr std::int8_t kModeHoming = 6;
constexpr std::uint16_t kBitNewSetpoint = 0x0010;
constexpr std::uint16_t kBitChangeImmediately = 0x0020;
constexpr std::uint16_t kBitRelative = 0x0040;
constexpr std::uint16_t kBitFaultReset = 0x0080;
constexpr std::uint16_t kBitHalt = 0x0100;

constexpr std::uint32_t kRpm = 0x00B44700;  // 0x60A9: 10^0, rpm (CiA 303-2 unit and time codes)

// The objects this drive reads or writes itself.
struct Played {
  std::uint16_t index;
  std::uint8_t subindex;
  const char* name;
};
constexpr Played kPlayed[] = {
    {0x603F, 0, "error code"},         {0x6007, 0, "abort connection option code"},
    {0x6040, 0, "controlword"},        {0x6041, 0, "statusword"},
    {0x605A, 0, "quick stop option code"}, {0x6060, 0, "modes of operation"},
    {0x6061, 0, "modes of operation display"}, {0x6064, 0, "position actual value"},
    {0x6065, 0, "following error window"}, {0x607A, 0, "target position"},
    {0x607D, 1, "min position limit"}, {0x607D, 2, "max position limit"},
    {0x6081, 0, "profile velocity"},   {0x6083, 0, "profile acceleration"},
    {0x6084, 0, "profile deceleration"}, {0x6085, 0, "quick stop deceleration"}};

std::string missing_drive_object(const ObjectDictionary& od) {
  for (const Played& p : kPlayed) {
    if (od.find(p.index, p.subindex) == nullptr) {
      char text[96];
      std::snprintf(text, sizeof(text), "no object 0x%04X:%02X (%s), which the drive plays", p.index, p.subindex, p.name);
      return text;
    }
  }
  if (const OdEntry* units = od.find(0x60A9, 0); units != nullptr) {
    if (units->default_value != kRpm) {
      char text[96];
      std::snprintf(text, sizeof(text), "0x60A9 = 0x%08X: a velocity unit the drive does not play (rpm only)",
                    units->default_value);
      return text;
    }
    if (od.find(0x6080, 0) == nullptr) return "no object 0x6080:00 (max motor speed), which a drive in rpm plays";
  }
  return CanopenDevice::check_communication_objects(od);
}

ObjectDictionary drive_dictionary(int node_id, const DriveDefaults& defaults, std::string& error) {
  ObjectDictionary od = dictionary_from_eds(defaults.eds, node_id, defaults.stored, missing_drive_object, error);
  if (!error.empty()) return od;
  // The mode in effect at power on is the stored one.
  OdEntry* display = od.find(0x6061, 0);
  display->value = display->default_value = od.get(0x6060, 0);
  return od;
}

ObjectDictionary checked_drive_dictionary(int node_id, const DriveDefaults& defaults) {
  std::string error;
  ObjectDictionary od = drive_dictionary(node_id, defaults, error);
  return dictionary_or_abort("Cia402Device", std::move(od), error);
}

}  // namespace

std::string Cia402Device::check(int node_id, const DriveDefaults& defaults) {
  std::string error;
  (void)drive_dictionary(node_id, defaults, error);
  return error;
}

Cia402Device::Cia402Device(int node_id, const DriveDefaults& defaults)
    : CanopenDevice(node_id, checked_drive_dictionary(node_id, defaults)),
      defaults_(defaults),
      rpm_units_(od().find(0x60A9, 0) != nullptr) {}

bool Cia402Device::operation_enabled() const { return power_ == Power::kOperationEnabled; }

bool Cia402Device::braking() const {
  if (velocity_ == 0.0) return false;
  return power_ == Power::kQuickStopActive || power_ == Power::kFaultReaction ||
         (power_ == Power::kOperationEnabled && (last_controlword_ & kBitHalt) != 0);
}

void Cia402Device::on_reset() {
  power_ = Power::kSwitchOnDisabled;
  last_controlword_ = 0;
  velocity_ = 0.0;
  demand_ = target_ = actual_;
  moving_ = has_buffered_ = false;
  ack_ = setpoint_busy_ = homing_attained_ = false;
  ack_set_us_ = ack_clear_us_ = -1;
}

std::uint32_t Cia402Device::check_write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) {
  (void)subindex;
  const auto as_i16 = static_cast<std::int16_t>(value & 0xFFFF);
  switch (index) {
    case 0x6060: {
      const auto mode = static_cast<std::int8_t>(value & 0xFF);
      return mode == kModeProfilePosition || mode == kModeHoming ? 0 : abort_code::kInvalidValue;
    }
    case 0x605A:
      return as_i16 == 0 || as_i16 == 1 || as_i16 == 2 || as_i16 == 5 || as_i16 == 6 ? 0 : abort_code::kInvalidValue;
    case 0x6007: return as_i16 >= 0 && as_i16 <= 3 ? 0 : abort_code::kInvalidValue;
    case 0x6081:
    case 0x6083:
    case 0x6084:
    case 0x6085:
      if (value == 0) return abort_code::kInvalidValue;
      // A velocity above the motor's maximum is refused, not clamped (the master must convert).
      return index == 0x6081 && rpm_units_ && value > od().get(0x6080, 0) ? abort_code::kInvalidValue : 0;
    default: return 0;
  }
}

void Cia402Device::after_write(std::uint16_t index, std::uint8_t subindex) {
  (void)subindex;
  if (index == 0x6060) od().set(0x6061, 0, od().get(0x6060, 0));  // the mode takes effect at once
}

void Cia402Device::on_rpdo(hal::TimeUs now_us) {
  now_us_ = now_us;
  apply_controlword(static_cast<std::uint16_t>(od().get(0x6040, 0)), now_us);
}

void Cia402Device::on_heartbeat_lost(int producer) {
  (void)producer;
  switch (od().get_signed(0x6007, 0)) {
    case 1: fault(kEmcyHeartbeat); break;
    case 2:
      if (power_ != Power::kFault && power_ != Power::kFaultReaction) {
        power_ = Power::kSwitchOnDisabled;
        velocity_ = 0.0;
        demand_ = actual_;
        moving_ = has_buffered_ = false;
      }
      break;
    case 3:
      if (power_ == Power::kOperationEnabled) start_quick_stop();
      break;
    default: break;
  }
}

void Cia402Device::fault(std::uint16_t code) {
  if (power_ == Power::kFault || power_ == Power::kFaultReaction) return;
  od().set(0x603F, 0, code);
  emergency(code, 0x01);
  const bool moving = power_ == Power::kOperationEnabled || power_ == Power::kQuickStopActive;
  power_ = moving ? Power::kFaultReaction : Power::kFault;
  moving_ = has_buffered_ = false;
}

void Cia402Device::start_quick_stop() {
  power_ = Power::kQuickStopActive;
  moving_ = has_buffered_ = false;  // the running move is abandoned
  if (od().get_signed(0x605A, 0) == 0) {  // disable drive function: stop at once
    velocity_ = 0.0;
    demand_ = actual_;
    power_ = Power::kSwitchOnDisabled;
  }
}

void Cia402Device::apply_controlword(std::uint16_t cw, hal::TimeUs now_us) {
  const std::uint16_t previous = last_controlword_;
  last_controlword_ = cw;
  if (power_ == Power::kFault) {
    if ((cw & kBitFaultReset) != 0 && (previous & kBitFaultReset) == 0) {  // transition 15 on the rising edge
      power_ = Power::kSwitchOnDisabled;
      od().set(0x603F, 0, 0);
      emergency(0x0000, 0x00);
    }
    return;
  }
  if (power_ == Power::kFaultReaction || (cw & kBitFaultReset) != 0) return;
  const bool disable_voltage = (cw & 0x0002) == 0;
  const bool quick_stop = (cw & 0x0006) == 0x0002;
  const bool shutdown = (cw & 0x0007) == 0x0006;
  const bool switch_on = (cw & 0x000F) == 0x0007;
  const bool enable = (cw & 0x000F) == 0x000F;
  const Power before = power_;
  switch (power_) {
    case Power::kSwitchOnDisabled:
      if (shutdown) power_ = Power::kReadyToSwitchOn;
      break;
    case Power::kReadyToSwitchOn:
      if (switch_on) power_ = Power::kSwitchedOn;
      if (enable) power_ = Power::kOperationEnabled;
      if (disable_voltage || quick_stop) power_ = Power::kSwitchOnDisabled;
      break;
    case Power::kSwitchedOn:
      if (enable) power_ = Power::kOperationEnabled;
      if (shutdown) power_ = Power::kReadyToSwitchOn;
      if (disable_voltage || quick_stop) power_ = Power::kSwitchOnDisabled;
      break;
    case Power::kOperationEnabled:
      if (quick_stop) start_quick_stop();
      if (disable_voltage) power_ = Power::kSwitchOnDisabled;
      if (shutdown) power_ = Power::kReadyToSwitchOn;
      if (switch_on) power_ = Power::kSwitchedOn;
      break;
    case Power::kQuickStopActive: {
      const std::int32_t option = od().get_signed(0x605A, 0);
      if (disable_voltage) power_ = Power::kSwitchOnDisabled;
      if (enable && option >= 5) power_ = Power::kOperationEnabled;  // transition 16
      break;
    }
    default: break;
  }
  if (before == Power::kOperationEnabled && power_ != Power::kOperationEnabled &&
      power_ != Power::kQuickStopActive) {
    velocity_ = 0.0;  // power stage off: the brake holds the winch
    demand_ = actual_;
    moving_ = has_buffered_ = false;
  }
  if (power_ != Power::kOperationEnabled) return;
  if (before != Power::kOperationEnabled) {
    demand_ = target_ = actual_;
    velocity_ = 0.0;
    moving_ = has_buffered_ = false;
    ack_ = setpoint_busy_ = false;
    ack_set_us_ = ack_clear_us_ = -1;
  }
  const bool bit4 = (cw & kBitNewSetpoint) != 0;
  const bool rising = bit4 && (previous & kBitNewSetpoint) == 0;
  const auto mode = static_cast<std::int8_t>(od().get(0x6061, 0) & 0xFF);
  if (mode == kModeProfilePosition) {
    if (rising) take_setpoint(now_us);
    if (!bit4 && setpoint_busy_ && ack_clear_us_ < 0) {
      // The handshake ends a PDO cycle after bit 4 is seen low, and never
      // before the acknowledgement itself was shown.
      ack_clear_us_ = std::max(now_us, ack_set_us_) + static_cast<hal::TimeUs>(1e6 * defaults_.ack_delay_s);
    }
  } else if (mode == kModeHoming && rising) {
    // Homing on the spot: the position counter is re-zeroed, the move is
    // whatever the homing method does; the master's target is not looked at.
    actual_ = demand_ = target_ = 0.0;
    velocity_ = 0.0;
    homing_attained_ = true;
  }
}

void Cia402Device::take_setpoint(hal::TimeUs now_us) {
  if (setpoint_busy_) return;  // set-point acknowledge still 1: a new set-point is not accepted
  double target = static_cast<double>(od().get_signed(0x607A, 0));
  if ((last_controlword_ & kBitRelative) != 0) target += target_;
  target = std::clamp(target, static_cast<double>(od().get_signed(0x607D, 1)),
                      static_cast<double>(od().get_signed(0x607D, 2)));
  if (moving_ && (last_controlword_ & kBitChangeImmediately) == 0) {
    buffered_target_ = target;
    has_buffered_ = true;
  } else {
    target_ = target;
    moving_ = true;
  }
  setpoint_busy_ = true;
  ack_set_us_ = now_us + static_cast<hal::TimeUs>(1e6 * defaults_.ack_delay_s);
}

double Cia402Device::counts_per_s(std::uint16_t index) const {
  double value = od().get(index, 0);
  // The factor group where the EDS has it: internal = written x numerator / divisor.
  const std::uint16_t factor = index == 0x6081 ? 0x6096 : 0x6097;
  const OdEntry* numerator = od().find(factor, 1);
  const OdEntry* divisor = od().find(factor, 2);
  if (numerator != nullptr && divisor != nullptr && divisor->value != 0) value = value * numerator->value / divisor->value;
  return rpm_units_ ? value * defaults_.counts_per_rev / 60.0 : value;
}

bool Cia402Device::brake(double deceleration, double dt_s) {
  const double dv = deceleration * dt_s;
  velocity_ = std::abs(velocity_) <= dv ? 0.0 : velocity_ - std::copysign(dv, velocity_);
  demand_ += velocity_ * dt_s;
  return velocity_ == 0.0;
}

void Cia402Device::move_towards_target(double dt_s) {
  const double v_max = counts_per_s(0x6081), accel = counts_per_s(0x6083), decel = counts_per_s(0x6084);
  const double to_go = target_ - demand_;
  if (std::abs(to_go) < 0.5 && std::abs(velocity_) <= decel * dt_s) {
    demand_ = target_;
    velocity_ = 0.0;
    return;
  }
  const double direction = to_go > 0.0 ? 1.0 : -1.0;
  const double stopping = velocity_ * velocity_ / (2.0 * decel);
  if (velocity_ * direction < 0.0 || std::abs(to_go) <= stopping) {
    const double dv = decel * dt_s;
    velocity_ = std::abs(velocity_) <= dv ? 0.0 : velocity_ - std::copysign(dv, velocity_);
  } else {
    velocity_ = std::clamp(velocity_ + direction * accel * dt_s, -v_max, v_max);
  }
  demand_ += velocity_ * dt_s;
  if ((target_ - demand_) * direction < 0.0) {  // passed the target within one step
    demand_ = target_;
    velocity_ = 0.0;
  }
}

void Cia402Device::advance(double dt_s) {
  constexpr double kStepS = 1e-3;
  while (dt_s > 0.0) {
    const double h = std::min(dt_s, kStepS);
    dt_s -= h;
    switch (power_) {
      case Power::kOperationEnabled:
        if ((last_controlword_ & kBitHalt) != 0) {
          brake(counts_per_s(0x6084), h);
        } else if (moving_) {
          move_towards_target(h);
          if (demand_ == target_ && velocity_ == 0.0) {
            moving_ = has_buffered_;
            target_ = has_buffered_ ? buffered_target_ : target_;
            has_buffered_ = false;
          }
        }
        break;
      case Power::kQuickStopActive: {
        const std::int32_t option = od().get_signed(0x605A, 0);
        const double decel = option == 1 || option == 5 ? counts_per_s(0x6084) : counts_per_s(0x6085);
        if (brake(decel, h) && (option == 1 || option == 2)) power_ = Power::kSwitchOnDisabled;
        break;
      }
      case Power::kFaultReaction:
        if (brake(counts_per_s(0x6085), h)) power_ = Power::kFault;
        break;
      default: break;
    }
    if (!blocked_) {
      const double step = defaults_.motor_max_speed * h;
      actual_ += std::clamp(demand_ - actual_, -step, step);
    }
    const bool powered = power_ == Power::kOperationEnabled || power_ == Power::kQuickStopActive;
    if (powered && std::abs(demand_ - actual_) > static_cast<double>(od().get(0x6065, 0))) fault(kEmcyFollowingError);
  }
}

std::uint16_t Cia402Device::compose_statusword() const {
  std::uint16_t sw = 0;
  switch (power_) {
    case Power::kSwitchOnDisabled: sw = 0x0040; break;
    case Power::kReadyToSwitchOn: sw = 0x0031; break;
    case Power::kSwitchedOn: sw = 0x0033; break;
    case Power::kOperationEnabled: sw = 0x0037; break;
    case Power::kQuickStopActive: sw = 0x0017; break;
    case Power::kFaultReaction: sw = 0x001F; break;
    case Power::kFault: sw = 0x0008; break;
  }
  sw |= 0x0200;  // remote
  const auto mode = static_cast<std::int8_t>(od().get(0x6061, 0) & 0xFF);
  const bool at_rest = velocity_ == 0.0;
  if (power_ == Power::kOperationEnabled && mode == kModeProfilePosition) {
    const bool halted = (last_controlword_ & kBitHalt) != 0;
    if (at_rest && (!moving_ || halted)) sw |= 0x0400;
    if (ack_) sw |= 0x1000;
  } else if (power_ == Power::kOperationEnabled && mode == kModeHoming && homing_attained_) {
    sw |= 0x1400;  // target reached + homing attained
  } else if (power_ == Power::kQuickStopActive && at_rest) {
    sw |= 0x0400;
  }
  return sw;
}

void Cia402Device::before_tpdo(hal::TimeUs now_us) {
  now_us_ = now_us;
  if (ack_set_us_ >= 0 && now_us >= ack_set_us_) {
    ack_ = true;
    ack_set_us_ = -1;
  }
  if (ack_clear_us_ >= 0 && ack_set_us_ < 0 && now_us >= ack_clear_us_) {
    ack_ = setpoint_busy_ = false;
    ack_clear_us_ = -1;
  }
  od().set(0x6041, 0, compose_statusword());
  od().set(0x6064, 0, static_cast<std::uint32_t>(static_cast<std::int32_t>(std::lround(actual_))));
}

}  // namespace cdpr::virtual_robot
