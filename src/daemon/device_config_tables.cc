#include "src/daemon/device_config_tables.h"

#include "drivers/can/eds.h"
#include "drivers/modbus/load_cell_presets.h"

namespace cdpr::daemon {
namespace {

using drivers::can::CanWinchConfig;
using drivers::can::DriveDescription;
using drivers::can::EncoderDescription;
using drivers::modbus::ByteOrder;
using drivers::modbus::ForceUnit;
using drivers::modbus::RegisterKind;
using drivers::modbus::ValueType;
using drivers::modbus::load_cell_preset;
using drivers::modbus::load_cell_preset_names;
constexpr IntRange kNodeId{1, 127};
constexpr IntRange kUnsigned32{0, 0xFFFFFFFFll, true};
constexpr IntRange kRegister{0, 65535};
constexpr IntRange kMask16{0, 0xFFFF, true};
constexpr NumberRange kMetresPerCount{-0.01, 0.01, false, false, true};

// The CiA 301 identity (0x1018) a node must report, drive and encoder alike.
template <class Description>
void identity_rows(Table<Description>& t) {
  t.integer("vendor_id", &Description::vendor_id, 0, kUnsigned32, "", "0x1018:01 expected; 0: not checked")
      .why("UNSIGNED32 object");
  t.integer("product_code", &Description::product_code, 0, kUnsigned32, "", "0x1018:02 expected; 0: not checked")
      .why("UNSIGNED32 object");
}

// An EDS key's check: empty, or a file libinih reads as an EDS (read once more at start).
constexpr const char* kEdsRange = "empty, or a readable EDS/DCF file";
std::string eds_problem(const std::string& path) {
  if (path.empty()) return "";
  std::string error;
  return drivers::can::Eds::load(path, error) ? "" : error;
}

}  // namespace

Table<WinchesConfig> winches_table() {
  Table<WinchesConfig> t("winches");
  t.string("endpoint", &WinchesConfig::endpoint, "",
           "\"socketcan:<interface>\", or \"unix:<path>\" for CAN frames over a Unix socket (the virtual robot)")
      .required();
  t.duration("heartbeat_timeout_ms", &WinchesConfig::heartbeat_timeout_us, 500, kMs, {10, 60'000},
             "a node silent this long is lost (>= 1.5 x its producer period)")
      .why("a drive or encoder that fell silent is noticed (and the run stopped) after this")
      .unsafe_unless_acknowledged("> 1000", [](const WinchesConfig& c) -> std::string {
        if (c.heartbeat_timeout_us <= 1'000'000) return "";
        return "longer than 1000 ms: a lost drive or encoder would go unnoticed while the others pull";
      });
  t.duration("resend_interval_ms", &WinchesConfig::resend_interval_us, 100, kMs, {10, 10'000},
             "NMT start / controlword resend while nothing moves on")
      .why("below 10 ms the resends crowd the bus; beyond 10 s a lost command stalls the start");
  t.number("max_move_m", &WinchesConfig::max_move_m, 250.0, {0.0, 1000.0, true}, "m",
           "a target farther than this from the payout is refused")
      .why("the bound on one command's travel; no CDPR cable is 1 km long");
  t.number("max_speed_mps", &WinchesConfig::max_speed_mps, 10.0, {0.0, 1000.0, true}, "m/s",
           "an encoder change faster than this between two readings is a fault (real time)")
      .why("an encoder jump check: above winches.drive.profile_velocity_mps, and no higher than 1 km/s, "
           "which only a simulated robot running faster than real time needs");
  t.integer("master_node_id", &WinchesConfig::master_node_id, 127, kNodeId, "",
            "the daemon's CANopen node id: heartbeat 0x700 + this")
      .why("CANopen node ids");
  t.duration("master_heartbeat_ms", &WinchesConfig::master_heartbeat_us, 100, kMs, {10, 1000},
             "the daemon's heartbeat period; the drives stop when it stays away")
      .why("the drives' consumer time (winches.drive.consumer_heartbeat_ms) must be >= 1.5 x this");
  t.duration("sdo_timeout_ms", &WinchesConfig::sdo_timeout_us, 200, kMs, {10, 10'000},
             "an SDO transfer without an answer this long is aborted")
      .why("the drives' configuration waits this per object; beyond 10 s a dead node stalls the start");
  t.number("position_limit_margin_m", &WinchesConfig::position_limit_margin_m, 0.5, {0.0, 1000.0}, "m",
           "the drives' software position limits 0x607D: [waypoints] min_payout .. max_payout widened by this, set "
           "at every enable")
      .why("room for a stop's overrun past the payout range; beyond 1 km the drive's limit guards nothing");
  return t;
}

Table<DriveDescription> drive_table() {
  Table<DriveDescription> t("winches.drive");
  identity_rows(t);
  t.string("eds", &DriveDescription::eds, "",
           "the drives' EDS/DCF file (CiA 306; e.g. /usr/share/cdpr-calibration/eds/maxon-epos4.eds): only objects it "
           "lists are configured, within their access type and range; empty: CiA 402 defaults assumed")
      .refusing(kEdsRange, [](const DriveDescription& d) { return eds_problem(d.eds); });
  t.integer("quick_stop_option", &DriveDescription::quick_stop_option, 6, {0, 6}, "",
            "0x605A: 0, 1, 2 (end switched off) or 5, 6 (stay in quick stop)")
      .why("3 and 4 stop at a current or voltage limit, not on a ramp")
      .refusing("0, 1, 2, 5, 6", [](const DriveDescription& d) -> std::string {
        if (d.quick_stop_option != 3 && d.quick_stop_option != 4) return "";
        return "must be 0, 1, 2, 5 or 6 (3 and 4 stop at a current or voltage limit), got " +
               std::to_string(d.quick_stop_option);
      });
  t.integer("abort_connection_option", &DriveDescription::abort_connection_option, 3, {0, 3}, "",
            "0x6007, the reaction to the daemon's heartbeat lost: 0 none, 1 fault, 2 off, 3 quick stop")
      .why("CiA 402 values; 3 quick-stops on the ramp of quick_stop_deceleration_mps2")
      .unsafe_unless_acknowledged("0", [](const DriveDescription& d) -> std::string {
        if (d.abort_connection_option != 0) return "";
        return "0: the drives would keep moving with the daemon gone (no reaction to a lost heartbeat)";
      });
  t.number("following_error_window_m", &DriveDescription::following_error_window_m, 0.1, {0.0, 2.0, true}, "m",
           "0x6065, of payout")
      .why("a blocked winch faults after this much lag; beyond 2 m a snagged cable winds on unchecked");
  t.number("profile_velocity_mps", &DriveDescription::profile_velocity_mps, 2.0, {0.0, 10.0, true}, "m/s",
           "0x6081 of the longest winch of a move; the others are scaled down")
      .why("no faster than the winches of a large CDPR (10 m/s), and below winches.max_speed_mps, whose jump "
           "check would stop every move");
  t.number("profile_acceleration_mps2", &DriveDescription::profile_acceleration_mps2, 1.0, {0.0, 20.0, true},
           "m/s^2", "0x6083, scaled the same way")
      .why("2 g of cable acceleration jerks the platform off its cables' tension band");
  t.number("profile_deceleration_mps2", &DriveDescription::profile_deceleration_mps2, 1.0, {0.0, 20.0, true},
           "m/s^2", "0x6084, scaled the same way")
      .why("2 g of cable deceleration jerks the platform off its cables' tension band");
  t.number("quick_stop_deceleration_mps2", &DriveDescription::quick_stop_deceleration_mps2, 2.0, {0.5, 20.0},
           "m/s^2", "0x6085")
      .why("the emergency ramp: at least the profile deceleration, and >= 0.5 (a 2 m/s cable stops within 4 s)");
  t.duration("heartbeat_producer_ms", &DriveDescription::heartbeat_producer_us, 100, kMs, {10, 1000, true},
             "0x1017 of the drive")
      .why("UNSIGNED16 whole ms; winches.heartbeat_timeout_ms must be >= 1.5 x this");
  t.duration("consumer_heartbeat_ms", &DriveDescription::consumer_heartbeat_us, 500, kMs, {10, 65'535, true},
             "0x1016: the drive quick-stops when the daemon is silent this long (>= 1.5 x master_heartbeat_ms)")
      .why("UNSIGNED16 whole ms; the drives run on without the daemon this long")
      .unsafe_unless_acknowledged("> 1000", [](const DriveDescription& d) -> std::string {
        if (d.consumer_heartbeat_us <= 1'000'000) return "";
        return "longer than 1000 ms: the drives would run on (2 m at 2 m/s) after the daemon is gone";
      });
  t.duration("pdo_event_timer_ms", &DriveDescription::pdo_event_timer_us, 20, kMs, {1, 1000, true},
             "TPDO1 (statusword + position) at least this often")
      .why("UNSIGNED16 whole ms; the daemon sees a winch's position no more often");
  return t;
}

Table<EncoderDescription> encoder_table() {
  Table<EncoderDescription> t("winches.encoder");
  identity_rows(t);
  t.string("eds", &EncoderDescription::eds, "",
           "the encoders' EDS/DCF file (e.g. /usr/share/cdpr-calibration/eds/kuebler-sendix.eds); empty: CiA 406 "
           "defaults assumed")
      .refusing(kEdsRange, [](const EncoderDescription& d) { return eds_problem(d.eds); });
  t.duration("heartbeat_producer_ms", &EncoderDescription::heartbeat_producer_us, 100, kMs, {10, 1000, true},
             "0x1017 of the encoder")
      .why("UNSIGNED16 whole ms; winches.heartbeat_timeout_ms must be >= 1.5 x this");
  t.duration("pdo_event_timer_ms", &EncoderDescription::pdo_event_timer_us, 20, kMs, {1, 1000, true},
             "TPDO1 (position value 0x6004) period")
      .why("UNSIGNED16 whole ms; the daemon sees a cable's payout no more often");
  t.integer("code_sequence", &EncoderDescription::code_sequence, -1, {-1, 1}, "",
            "0x6000 bit 0 the encoders must have: 0 counting up clockwise, 1 counter-clockwise; -1: not checked")
      .why("CiA 406 code sequence bit; an encoder counting the other way reverses the payout");
  t.integer("counts_per_revolution", &EncoderDescription::counts_per_revolution, 0, kUnsigned32, "",
            "0x6001 the encoders must have; 0: not checked")
      .why("CiA 406 UNSIGNED32");
  t.integer("measuring_range", &EncoderDescription::measuring_range, 0, kUnsigned32, "",
            "0x6002 the encoders must have (0x6004 wraps there); 0: not checked, read")
      .why("CiA 406 UNSIGNED32");
  return t;
}

Table<drivers::can::WinchMechanics> mechanics_table() {
  Table<drivers::can::WinchMechanics> t("winches.mechanics");
  t.number("drum_diameter_m", &drivers::can::WinchMechanics::drum_diameter_m, 0.0, {0.0, 10.0}, "m",
           "cable drum at the cable's centre line; 0: not given (drives must then count position increments, "
           "0x60A9)")
      .why("the drums of cable robots up to 250 m are well under 10 m");
  t.number("gear_ratio", &drivers::can::WinchMechanics::gear_ratio, 1.0, {0.0, 10'000.0, true}, "",
           "motor revolutions per drum revolution; payout per motor revolution = pi x drum_diameter_m / gear_ratio")
      .why("a winch gearbox reduces by well under 10000:1");
  return t;
}

Table<CanWinchConfig> winch_table() {
  Table<CanWinchConfig> t("winches.winch");
  t.integer("drive_node_id", &CanWinchConfig::drive_node_id, IntDefault::per_cable(1), kNodeId, "",
            "CiA 402 drive")
      .why("CANopen node ids");
  t.integer("encoder_node_id", &CanWinchConfig::encoder_node_id, IntDefault::per_cable(11), {0, 127}, "",
            "CiA 406 encoder; 0: use the drive's position")
      .why("CANopen node ids");
  t.number("encoder_m_per_count", &CanWinchConfig::encoder_m_per_count, 1e-5, kMetresPerCount, "m",
           "payout per encoder count; the sign gives the direction")
      .why("a count of more than 1 cm is no winch encoder; 0 would read every payout as 0");
  t.number("drive_m_per_count", &CanWinchConfig::drive_m_per_count, 1e-5, kMetresPerCount, "m",
           "payout per drive position count")
      .why("a count of more than 1 cm is no drive encoder; 0 would make every target 0");
  t.string("drive_eds", &CanWinchConfig::drive_eds, "",
           "this winch's drive's EDS/DCF where it differs from winches.drive.eds (another make, a replacement); "
           "empty: that one")
      .refusing(kEdsRange, [](const CanWinchConfig& c) { return eds_problem(c.drive_eds); });
  t.string("encoder_eds", &CanWinchConfig::encoder_eds, "",
           "this winch's encoder's EDS/DCF where it differs from winches.encoder.eds; empty: that one")
      .refusing(kEdsRange, [](const CanWinchConfig& c) { return eds_problem(c.encoder_eds); });
  return t;
}

Table<LoadCellConfig> load_cell_table() {
  Table<LoadCellConfig> t("load_cell");
  t.string("endpoint", &LoadCellConfig::endpoint, "",
           "\"tcp:<host>:<port>\" (Modbus TCP) or \"rtu:<serial device>\" (Modbus RTU)")
      .required();
  t.integer("baud", &LoadCellConfig::baud, 19200, {300, 4'000'000}, "bit/s", "RTU only")
      .why("the rates serial adapters offer");
  t.choice("parity", &LoadCellConfig::parity, {{"N", 'N'}, {"E", 'E'}, {"O", 'O'}}, 'N', "RTU only");
  t.integer("data_bits", &LoadCellConfig::data_bits, 8, {5, 8}, "", "RTU only").why("what a UART frames");
  t.integer("stop_bits", &LoadCellConfig::stop_bits, 1, {1, 2}, "", "RTU only").why("what a UART frames");
  t.integer("slave_id", &LoadCellConfig::slave_id, 1, {0, 255}, "",
            "unit identifier: RTU 1..247 (0 is broadcast); TCP 0..247 or 255")
      .why("Modbus unit identifiers");
  t.choice("register_kind", &LoadCellConfig::register_kind,
           {{"holding", RegisterKind::kHolding}, {"input", RegisterKind::kInput}}, RegisterKind::kHolding,
           "read holding (function 0x03) or input (0x04) registers");
  std::vector<std::pair<std::string, std::string>> presets;
  for (const std::string_view name : load_cell_preset_names()) presets.emplace_back(name, name);
  t.choice("preset", &LoadCellConfig::preset, presets, std::string("legacy-float32"),
           "the transmitter's register map (docs/fieldbus.md); the keys below override its values")
      .then([](LoadCellConfig& c) { c.map = *load_cell_preset(c.preset); });
  // The map's keys; their defaults are those of the default preset.
  t.integer("value_address", [](auto& c) -> auto& { return c.map.value_address; }, 0, kRegister, "",
            "protocol address (0-based: a manual's 40001 is 0); within 16 registers of the status")
      .why("Modbus register addresses");
  t.choice("value_type", [](auto& c) -> auto& { return c.map.value_type; },
           {{"float32", ValueType::kFloat32}, {"int32", ValueType::kInt32}, {"uint32", ValueType::kUint32},
            {"int16", ValueType::kInt16}, {"uint16", ValueType::kUint16}},
           ValueType::kFloat32, "the value's encoding");
  t.choice("byte_order", [](auto& c) -> auto& { return c.map.byte_order; },
           {{"ABCD", ByteOrder::kABCD}, {"CDAB", ByteOrder::kCDAB}, {"BADC", ByteOrder::kBADC},
            {"DCBA", ByteOrder::kDCBA}},
           ByteOrder::kABCD, "bytes A (most significant) .. D as the registers carry them");
  t.integer("decimals", [](auto& c) -> auto& { return c.map.decimals; }, 0, {0, 9}, "",
            "integer values: the number / 10^decimals")
      .why("a 32-bit value has at most 10 digits");
  t.number("scale", [](auto& c) -> auto& { return c.map.scale; }, 1.0, {-1e6, 1e6, false, false, true}, "",
           "times the value, before the unit (-1 for a reversed cell)")
      .why("0 reads every tension as 0 (the slack and overload checks blind); 1e6 turns a count into 100 t");
  t.choice("unit", [](auto& c) -> auto& { return c.map.unit; },
           {{"N", ForceUnit::kNewton}, {"kg", ForceUnit::kKilogram}, {"lbf", ForceUnit::kPoundForce}},
           ForceUnit::kNewton, "the value's unit (kg: kilogram-force)");
  t.integer("status_address", [](auto& c) -> auto& { return c.map.status_address; }, 2, {-1, 65535}, "",
            "-1: the device has no status register")
      .why("Modbus register addresses");
  t.integer("stable_mask", [](auto& c) -> auto& { return c.map.stable.mask; }, 0x0001, kMask16, "",
            "status bits meaning \"stable\"; 0: always stable")
      .why("bits of one 16-bit register");
  t.choice("stable_when", [](auto& c) -> auto& { return c.map.stable.active_when_set; },
           {{"set", true}, {"clear", false}}, true, "stable when a bit is set, or when all are clear");
  t.integer("error_mask", [](auto& c) -> auto& { return c.map.error.mask; }, 0x0002, kMask16, "",
            "status bits meaning \"error\"; 0: never an error")
      .why("bits of one 16-bit register");
  t.choice("error_when", [](auto& c) -> auto& { return c.map.error.active_when_set; },
           {{"set", true}, {"clear", false}}, true, "an error when any is set, or when all are clear (\"data ok\")");
  t.integer("sign_mask", [](auto& c) -> auto& { return c.map.sign_mask; }, 0, kMask16, "",
            "the value is a magnitude, negative when one of these bits is set; 0: signed value")
      .why("bits of one 16-bit register");
  t.duration("response_timeout_ms", &LoadCellConfig::response_timeout_us, 200, kMs, {1, 10'000}, "per try of a read")
      .why("beyond 10 s a dead cell holds the reader that long per try");
  t.integer("retries", &LoadCellConfig::retries, 2, {0, 10}, "",
            "per read on timeouts, CRC or framing errors, lost connections (never on an exception reply)")
      .why("each try can take response_timeout_ms; fault_timeout_ms bounds them in time");
  t.duration("poll_interval_ms", &LoadCellConfig::poll_interval_us, 20, kMs, {1, 1000},
             "one read every this long, on a thread of its own")
      .why("the tension checks see a reading no more often");
  t.duration("fault_timeout_ms", &LoadCellConfig::fault_timeout_us, 1000, kMs, {10, 60'000},
             "no good reading for this long stops a run")
      .why("the winches move without a tension reading this long")
      .unsafe_unless_acknowledged("> 2000", [](const LoadCellConfig& c) -> std::string {
        if (c.fault_timeout_us <= 2'000'000) return "";
        return "longer than 2000 ms: the winches would move on (4 m at 2 m/s) with no tension reading";
      });
  return t;
}

Table<PoseConfig> pose_table() {
  Table<PoseConfig> t("pose");
  t.string("endpoint", &PoseConfig::endpoint, "",
           "the localization system's pose stream: \"tcp:<host>:<port>\" or \"unix:<path>\"")
      .required();
  t.duration("connect_timeout_ms", &PoseConfig::connect_timeout_us, 1000, kMs, {1, 60'000}, "")
      .why("the daemon's loop waits no longer than a minute for a connection");
  return t;
}

Table<ButtonConfig> button_table() {
  Table<ButtonConfig> t("button");
  t.choice("kind", &ButtonConfig::gpio, {{"gpio", true}, {"none", false}}, true,
           "a GPIO line (libgpiod), or none: start only with `calibctl start`");
  t.string("chip", &ButtonConfig::chip, "gpiochip0", "name, number or /dev path");
  t.integer("line", &ButtonConfig::line, 17, {0, 65535}, "", "line offset on the chip")
      .why("GPIO line offsets");
  t.boolean("active_low", &ButtonConfig::active_low, true, "");
  t.duration("debounce_ms", &ButtonConfig::debounce_us, 50, kMs, {1, 1000}, "")
      .why("a press shorter than this is ignored; a second is a long press");
  return t;
}

}  // namespace cdpr::daemon
