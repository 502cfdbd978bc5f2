#pragma once
// The virtual robot's CANopen nodes: per winch one CiA 402 drive
// (cia402_device.h) and one CiA 406 cable encoder (cia406_device.h), each
// with its own object dictionary and SDO server starting from the
// profiles' defaults, so cdpr-calibd has to configure them as it would real
// devices. None of the master's protocol code (drivers/can) is used here:
// a misreading of the standard on either side shows as a failure.
//
// The drives own the winch motion: each runs its own profile (0x6081,
// 0x6083, 0x6084) in simulated time and the physics follows their
// positions. Counts: drive position = payout / drive_m_per_count (same
// zero); encoder position = (payout + noise) / encoder_m_per_count, reported
// modulo the encoder's measuring range.
// Time: on_frame/poll take real monotonic [us] (heartbeats, PDO timers,
// consumer heartbeat); advance() takes simulated seconds. Not thread-safe.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/can/can_frame.h"
#include "hal/clock.h"
#include "sim/rng.h"
#include "virtual-robot/cia402_device.h"
#include "virtual-robot/cia406_device.h"
#include "virtual-robot/robot_physics.h"

namespace cdpr::virtual_robot {

// The EDS files the nodes play: the shipped virtual devices', or a vendor
// quirk profile (docs/fieldbus.md, "Vendor quirks") as --canopen-quirks
// names it, each a shipped EDS file: two-tpdo-encoder (encoders with TPDO1-2
// only and no RPDO, as Kübler Sendix and SIKO), rtr-bit30 (drives keeping
// COB-ID bit 30 at 1, Lika), no-type-255 (drives whose transmission types
// stop at 254, Lika), rpm-units (drives in rpm and rpm/s, maxon EPOS4,
// Nanotec). "a,b" combines an encoder's profile with a drive's.
struct CanopenQuirks {
  std::string drive_eds = "cdpr-virtual-drive.eds";
  std::string encoder_eds = "cdpr-virtual-encoder.eds";
};

// names -> the profile's files ("" or "none": the plain ones); nullopt with
// `error` for an unknown name or two profiles of the same device.
std::optional<CanopenQuirks> parse_canopen_quirks(const std::string& names, std::string& error);
// All profiles, one by one (for tests and make demo).
const std::vector<std::string>& canopen_quirk_names();

struct NodeLayout {
  std::array<int, kCableCount> drive_node_id{1, 2, 3, 4};
  std::array<int, kCableCount> encoder_node_id{11, 12, 13, 14};
  double encoder_m_per_count = 1.0e-5;
  double drive_m_per_count = 1.0e-5;
  std::uint32_t encoder_range_counts = 1u << 26;  // 0x6002: 671 m at 1e-5 m per count
  std::int8_t drive_power_on_mode = 0;            // 0x6060 at power on: 0 none, 1 profile position, 6 homing
  double encoder_noise_m = 0.0;  // 1-sigma per reading [m]
  // What the drives and encoders play: a shipped file by default (quirks), or any other.
  DeviceEds drive_eds = shipped_eds(CanopenQuirks{}.drive_eds);
  DeviceEds encoder_eds = shipped_eds(CanopenQuirks{}.encoder_eds);
  // Drives in rpm: the winch's mechanics the daemon must be told in
  // [winches.mechanics] (motor counts per revolution follow from drive_m_per_count).
  double drum_diameter_m = 0.2;
  double gear_ratio = 10.0;
};

class CanopenNodes {
 public:
  // Aborts when check(layout) refuses.
  CanopenNodes(const NodeLayout& layout, RobotPhysics& physics, sim::Rng rng, hal::TimeUs now_us);
  // Empty when the nodes can play the layout's EDS files, else why not.
  static std::string check(const NodeLayout& layout);
  // The layout's quirk profile: its drives' and encoders' shipped EDS files.
  static void apply(const CanopenQuirks& quirks, NodeLayout& layout);

  // A frame from the bus (the daemon).
  void on_frame(const drivers::can::CanFrame& frame, hal::TimeUs now_us);
  // Moves the drives by dt_s simulated seconds and the physics' payouts with them.
  void advance(double dt_s);
  // Appends the frames due at `now_us`.
  void poll(hal::TimeUs now_us, std::vector<drivers::can::CanFrame>& out);

  // Node `id` stops talking (heartbeat and PDOs), as a cut cable would.
  void silence(int node_id, bool silent);
  // Encoder `winch` reads `slip_m` more than the payout from now on (it
  // slipped on its drum: operation_faults.h).
  void add_encoder_slip(int winch, double slip_m) { encoder_slip_m_[winch] += slip_m; }
  // Every drive at rest (no profile running).
  bool winches_still() const;
  // A drive is braking to rest on a stop (Cia402Device::braking()).
  bool any_drive_braking() const;
  // Every motor still (Cia402Device::axis_still()): no move running or a halted one.
  bool axes_still() const;
  Cia402Device& drive(int winch) { return *drives_[winch]; }
  Cia406Device& encoder(int winch) { return *encoders_[winch]; }

 private:
  NodeLayout layout_;
  RobotPhysics& physics_;
  sim::Rng rng_;
  std::array<std::unique_ptr<Cia402Device>, kCableCount> drives_;
  std::array<std::unique_ptr<Cia406Device>, kCableCount> encoders_;
  std::vector<BusFrame> scratch_;
  std::array<double, kCableCount> encoder_slip_m_{};
};

}  // namespace cdpr::virtual_robot
