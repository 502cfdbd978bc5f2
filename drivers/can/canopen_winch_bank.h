#pragma once
// hal::WinchBank over CANopen: per winch one CiA 402 drive (profile position
// mode) and optionally one CiA 406 cable encoder, on any CanTransport
// (SocketCAN or the virtual robot's Unix socket: the protocol code is the
// same).
//
// Per node, from open() or its boot-up: NMT enter pre-operational, then
// configure-and-verify over SDO (device_configuration.h: identity, PDO
// mapping, COB-IDs, transmission types, event timers, drive parameters,
// heartbeats; the encoder's measuring range 0x6002 read), then NMT start.
// A drive is first asked its velocity unit (0x60A9) and max motor speed
// (0x6080): its profile is written in its own units, and a unit the
// daemon cannot convert to, or a profile velocity above 0x6080, is a
// latched fault naming the node.
// A node that does not answer is tried again every resend interval; a
// refusal or a read-back mismatch is a latched fault naming node, object
// and values, and the drive is never enabled. Before every enable the
// drive's mode is written (0x6060 = 1) and 0x6061 read until it shows it,
// and its software position limits 0x607D set from the payout range.
// The master produces its own heartbeat (0x700 + master_node_id) every
// master_heartbeat_us; the drives' consumer heartbeat (0x1016) makes them
// stop on their own when the master goes silent.
// A node is alive when its heartbeat is fresh and says operational and its
// TPDO is fresh (both within heartbeat_timeout_us). A drive that reboots
// is configured and started again but NOT re-enabled: it shows kDisabled
// until enable().
//
// Units: payout [m] = encoder counts x encoder_m_per_count, the encoder's
// UNSIGNED32 position unwrapped across its measuring range
// (encoder_unwrap.h; a jump faster than max_speed_mps is a latched fault;
// the first reading after a (re)start is taken nearest the position kept
// in last_positions_path, else nearest the middle of min/max_payout_m, so a
// cable anywhere in the measuring range reads the same after a restart).
// Targets go to the drive relative to the present: target_counts =
// actual_counts + round((target_m - payout_m) / drive_m_per_count), so
// motor and cable encoder need not share a zero; |target_m - payout_m| <=
// max_move_m. Without an encoder node the drive's own position (INTEGER32)
// is the payout.
//
// Errors, counters, allocation: see hal/winch_bank.h. update() reads at most
// max_frames_per_update frames, so a babbling bus cannot starve the loop;
// SDO transfers advance one frame per node per update(), never waiting.
// The transport is made by the connector at open(), so open() after a lost
// connection reconnects.

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/can/can_transport.h"
#include "drivers/can/cia402_drive.h"
#include "drivers/can/device_configuration.h"
#include "drivers/can/eds.h"
#include "drivers/can/encoder_unwrap.h"
#include "drivers/can/last_positions.h"
#include "drivers/can/node_configurator.h"
#include "hal/winch_bank.h"

namespace cdpr::drivers::can {

struct CanWinchConfig {
  int drive_node_id = 0;             // 1..127
  int encoder_node_id = 0;           // 1..127, != drive; 0: no encoder node, use the drive's position
  double encoder_m_per_count = 0.0;  // payout [m] per encoder count, sign gives direction; != 0
  double drive_m_per_count = 0.0;    // payout [m] per drive position count; != 0
  // This winch's drive's and encoder's EDS where they differ from the
  // others' (a replaced or another make of device); empty: DriveDescription::eds / EncoderDescription::eds.
  std::string drive_eds = {};
  std::string encoder_eds = {};
};

// The winch between motor and cable, for drives that count motor
// revolutions (drive_units.h). All winches alike.
struct WinchMechanics {
  double drum_diameter_m = 0.0;  // cable drum, at the cable's centre line; 0: not given
  double gear_ratio = 1.0;       // motor revolutions per drum revolution
  // Payout per motor revolution [m]; 0 when the drum is not given.
  double m_per_motor_rev() const;
};

struct CanWinchBankConfig {
  std::vector<CanWinchConfig> winches;
  hal::TimeUs heartbeat_timeout_us = 500'000;  // node heartbeat and TPDO age limit (>= 1.5 x their periods)
  hal::TimeUs resend_interval_us = 100'000;    // NMT start / controlword resend when nothing moves on
  int max_frames_per_update = 256;
  double max_move_m = 250.0;      // largest |target - payout| one command may ask for [m]
  double max_speed_mps = 10.0;    // fastest a cable can pay out: bounds the change between two readings [m/s]
  int master_node_id = 127;       // the heartbeat COB-ID 0x700 + this, and the drives' 0x1016 producer
  hal::TimeUs master_heartbeat_us = 100'000;
  hal::TimeUs sdo_timeout_us = 200'000;
  // How long a drive may take to show the written mode in 0x6061 (CiA 402
  // 6.2.7: the display follows when the mode has taken effect), read every
  // mode_poll_interval_us meanwhile.
  hal::TimeUs mode_switch_timeout_us = 1'000'000;
  hal::TimeUs mode_poll_interval_us = 10'000;
  // The payout range the winches may travel [m, encoder units] ([waypoints]
  // min_payout / max_payout) and the margin around it: at every enable the
  // drive's software position limits 0x607D are set to it, in drive counts
  // from the present position. Infinite (or beyond INTEGER32): the full range.
  double min_payout_m = -std::numeric_limits<double>::infinity();
  double max_payout_m = std::numeric_limits<double>::infinity();
  double position_limit_margin_m = 0.5;
  // Where each encoder's last unwrapped position is kept (last_positions.h;
  // the daemon: <state_dir>/winch-positions); empty: not kept. Written
  // whenever a winch's position moved an eighth of its measuring range
  // from the one kept, and at close(); read at construction: a first
  // reading after a (re)start is taken nearest it, not nearest the middle
  // of min/max_payout_m.
  std::string last_positions_path;
  DriveDescription drive;
  EncoderDescription encoder;
  WinchMechanics mechanics;
};

using CanConnector = std::function<hal::Result<std::unique_ptr<CanTransport>>()>;

// "socketcan:can0" or "unix:/run/robot/can.sock" -> connector. Anything else:
// a connector that fails with kInvalidArgument.
CanConnector make_can_connector(const std::string& endpoint);

// Empty when valid, else the first problem ("winch 2: drive node id 0 out of 1..127").
std::string validate(const CanWinchBankConfig& config);

class CanopenWinchBank final : public hal::WinchBank {
 public:
  // Loads the nodes' EDS files and fits the configuration to them.
  CanopenWinchBank(CanWinchBankConfig config, CanConnector connector);

  // Why the configuration does not fit the devices' EDS files ("node 11:
  // sendix.eds [6002] AccessType=ro: ..."), or a file that cannot be read;
  // empty when it fits. open() refuses while it is set.
  const std::string& setup_error() const { return setup_error_; }
  // The nodes described by no EDS ("drives 1, 2, 3, 4"): configured with the CiA defaults.
  std::string nodes_without_eds() const;

  int winch_count() const override { return static_cast<int>(config_.winches.size()); }
  hal::Status open() override;
  void close() override;
  hal::Status update(hal::TimeUs now_us) override;
  hal::WinchStatus status(int winch) const override;
  std::string fault_text(int winch) const override;
  hal::WinchBankCounters counters() const override { return counters_; }
  // Drive first, then the encoder (when the winch has one).
  int node_count(int winch) const override;
  hal::NodeStatus node_status(int winch, int node) const override;
  hal::Status reset_faults() override;
  hal::Status enable() override;
  hal::Status disable() override;
  hal::Status set_target_payout(int winch, double payout_m) override;
  // Coordinated: per move, each drive's profile velocity, acceleration,
  // deceleration and quick-stop deceleration (0x6081, 0x6083, 0x6084,
  // 0x6085) are the description's scaled by |delta_i| / max |delta|
  // (move_profile.h), written over SDO, and then all targets are sent in
  // the same cycle: every winch runs a scaled copy of the longest winch's
  // trapezoid, so all start and arrive together, and stop together on a
  // halt, a quick stop or a lost master heartbeat, the payouts staying on
  // the straight line between the two waypoints. A profile any drive
  // refuses moves none of them (that winch's latched fault says why).
  hal::Status set_target_payouts(const double* payouts_m) override;
  hal::Status halt() override;
  hal::Status quick_stop() override;
  bool motion_finished() const override;

 private:
  struct Node {
    Node(int node_id, hal::TimeUs sdo_timeout_us) : id(node_id), configurator(node_id, sdo_timeout_us) {}
    int id = 0;
    hal::TimeUs last_heartbeat_us = -1;
    NmtState nmt_state = NmtState::kBootUp;
    hal::TimeUs last_pdo_us = -1;
    bool configured = false;
    hal::TimeUs configure_at_us = -1;  // when to (re)start the configuration; -1: not planned
    NodeConfigurator configurator;
    std::shared_ptr<const Eds> eds;    // null: none, the profile's defaults assumed
    std::vector<SdoStep> probe_steps;  // asked before `steps` are made (drive: units); empty: none
    bool probed = false;
    std::vector<SdoStep> steps;
    hal::TimeUs last_start_sent_us = -1;
    std::uint16_t emcy_code = 0;  // its last EMCY, for the operator's status
    std::uint8_t emcy_register = 0;
  };
  // kCheckMode: 0x6060 written; kAwaitMode: 0x6061 read until it shows the
  // mode (drives switch asynchronously) or mode_switch_timeout_us passes.
  enum class EnableStep { kNone, kCheckMode, kAwaitMode, kGoalSet };
  struct Winch {
    Node drive_node;
    Node encoder_node;  // id 0: none
    Cia402Drive drive;
    DriveUnits units;  // of 0x6081/0x6083/0x6084/0x6085, from the drive's probe
    EncoderUnwrap encoder;
    hal::TimeUs encoder_time_us = -1;
    double target_payout_m = 0.0;
    EnableStep enable = EnableStep::kNone;
    bool mode_check_started = false;
    std::vector<SdoStep> profile_steps;  // this move's 0x6081/0x6083/0x6084/0x6085
    bool profile_pending = false;       // written before the coordinated target goes out
    std::int32_t pending_target_counts = 0;
    std::string fault;  // latched: configuration refused or mismatched, encoder jump
    std::string emergency;  // the latest EMCY of its nodes, for messages
    std::vector<SdoStep> error_code_steps;  // 0x603F, read once per drive fault
    bool error_code_asked = false;
    std::string error_code;  // "0x603F = 0x8611 (following error)" of the present fault
    hal::TimeUs mode_deadline_us = 0;  // kAwaitMode: give up after this
    hal::TimeUs mode_read_at_us = 0;   // kAwaitMode: the next read of 0x6061
    std::uint16_t error_code_value = 0;  // 0x603F of the present fault as read
    std::vector<SdoStep> enable_steps;  // 0x6060 and 0x607D of this enable
  };

  hal::Status send(const CanFrame& frame);
  void dispatch(const CanFrame& frame, hal::TimeUs now_us);
  void on_position(Winch& winch, std::uint32_t raw, hal::TimeUs now_us);
  void on_heartbeat(Winch& winch, Node& node, NmtState state, hal::TimeUs now_us);
  void on_emergency(Winch& winch, Node& node, const CanFrame& frame);
  hal::Status service_node(Winch& winch, Node& node, hal::TimeUs now_us);
  // The probe's answers made into `node.steps`; empty, else why the node cannot be configured.
  std::string configure_from_probe(Winch& winch, Node& node);
  // The drive's steps for the units its unit objects say (drive_units.h), fitted to its EDS; empty, else why not.
  std::string make_drive_steps(Winch& winch, const DriveUnitObjects& unit_objects,
                               std::optional<std::uint32_t> max_motor_speed);
  // The unit objects from `value` (index, subindex -> the probe's or the EDS's value, nullopt where absent).
  static DriveUnitObjects unit_objects(
      const std::function<std::optional<std::uint32_t>(std::uint16_t, std::uint8_t)>& value);
  void load_eds(Node& node, const std::string& path, std::map<std::string, std::shared_ptr<const Eds>>& loaded);
  // Loads the EDS files and fits the steps to them; a misfit goes to setup_error_.
  void fit_to_devices();
  hal::Status service_enable(Winch& winch, hal::TimeUs now_us);
  // 0x6060 and 0x607D from min/max_payout_m and the present positions (0x6061 is read after them).
  std::vector<SdoStep> enable_steps(const Winch& winch) const;
  // The middle of min/max_payout_m in position counts: where a first reading is unwrapped to.
  std::int64_t payout_centre_counts(const Winch& winch) const;
  // Keeps the encoders' positions (config_.last_positions_path) when one moved
  // an eighth of its range from the one kept, or with `always`.
  void keep_positions(bool always);
  hal::Status service_coordinated_move(hal::TimeUs now_us);
  // Reads 0x603F of a drive that entered fault (what EMCY may have missed).
  hal::Status service_error_code(Winch& winch, hal::TimeUs now_us);
  // The drive target for `payout_target_m`, or why not.
  hal::Result<std::int32_t> target_counts(int winch, double payout_target_m);
  hal::Status send_master_heartbeat(hal::TimeUs now_us);
  // Sends what the drive state machines want now; first error wins.
  hal::Status poll_drives(hal::TimeUs now_us);
  // Disable or quick stop: cancels enabling and a move not yet sent.
  hal::Status stop_all(Cia402Drive::Goal goal);
  void cancel_coordinated_move();
  bool node_alive(const Node& node) const;
  double payout_m(const Winch& winch) const;
  hal::Status check_open() const;

  CanWinchBankConfig config_;
  CanConnector connector_;
  std::vector<std::optional<std::int64_t>> kept_counts_;  // per winch, as last written
  std::string setup_error_;
  std::unique_ptr<CanTransport> transport_;
  std::vector<Winch> winches_;
  std::vector<SdoStep> mode_write_steps_;    // 0x6060 written
  std::vector<SdoStep> mode_display_steps_;  // 0x6061 read
  std::uint32_t mode_wanted_ = 0;            // what 0x6061 must show
  bool coordinated_move_pending_ = false;
  hal::TimeUs now_us_ = 0;
  hal::TimeUs last_master_heartbeat_us_ = -1;
  hal::WinchBankCounters counters_;
};

}  // namespace cdpr::drivers::can
