// cdpr-calibd.toml: the shipped example parses to the documented defaults,
// and bad input is refused naming file, line and key.

#include <string>

#include <gtest/gtest.h>

#include "config_text.h"
#include "src/daemon/daemon_config.h"

namespace cdpr::daemon {
namespace {

const std::string kExample = std::string(CDPR_SOURCE_DIR) + "/systemd/cdpr-calibd.toml";

TEST(DaemonConfig, TheShippedExampleParsesToTheDefaults) {
  // GIVEN the example configuration installed with the unit
  // WHEN it is read
  const auto config = read_daemon_config(kExample);
  // THEN it parses, and every value it shows equals the built-in default
  ASSERT_TRUE(config) << config.error().message();
  const DaemonConfig defaults = default_daemon_config();
  EXPECT_EQ(config->robot_path, "/etc/cdpr-calib/robot.toml");
  EXPECT_EQ(config->store.state_dir, defaults.store.state_dir);
  EXPECT_EQ(config->store.history_depth, defaults.store.history_depth);
  EXPECT_EQ(config->control_socket, defaults.control_socket);
  EXPECT_EQ(config->control_socket_group, "");  // the daemon's own group
  EXPECT_EQ(config->loop_period_us, defaults.loop_period_us);
  ASSERT_EQ(config->winches.winches.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(config->winches.winches[i].drive_node_id, defaults.winches.winches[i].drive_node_id);
    EXPECT_EQ(config->winches.winches[i].encoder_node_id, defaults.winches.winches[i].encoder_node_id);
    EXPECT_EQ(config->winches.winches[i].encoder_m_per_count, defaults.winches.winches[i].encoder_m_per_count);
  }
  EXPECT_EQ(config->winches.heartbeat_timeout_us, defaults.winches.heartbeat_timeout_us);
  EXPECT_EQ(config->winches.max_move_m, defaults.winches.max_move_m);
  EXPECT_EQ(config->winches.master_node_id, defaults.winches.master_node_id);
  EXPECT_EQ(config->winches.master_heartbeat_us, defaults.winches.master_heartbeat_us);
  EXPECT_EQ(config->winches.sdo_timeout_us, defaults.winches.sdo_timeout_us);
  const drivers::can::DriveDescription& drive = config->winches.drive;
  EXPECT_EQ(drive.quick_stop_option, defaults.winches.drive.quick_stop_option);
  EXPECT_EQ(drive.abort_connection_option, defaults.winches.drive.abort_connection_option);
  EXPECT_EQ(drive.profile_velocity_mps, defaults.winches.drive.profile_velocity_mps);
  EXPECT_EQ(drive.quick_stop_deceleration_mps2, defaults.winches.drive.quick_stop_deceleration_mps2);
  EXPECT_EQ(drive.consumer_heartbeat_us, defaults.winches.drive.consumer_heartbeat_us);
  EXPECT_EQ(drive.pdo_event_timer_us, defaults.winches.drive.pdo_event_timer_us);
  EXPECT_EQ(config->winches.encoder.pdo_event_timer_us, defaults.winches.encoder.pdo_event_timer_us);
  EXPECT_EQ(config->winches.endpoint, "socketcan:can0");  // required: an example, not a default
  EXPECT_EQ(config->load_cell.endpoint, "rtu:/dev/ttyUSB0");
  EXPECT_EQ(config->load_cell.response_timeout_us, defaults.load_cell.response_timeout_us);
  EXPECT_EQ(config->pose.endpoint, "tcp:127.0.0.1:5600");
  EXPECT_EQ(config->button.gpio, defaults.button.gpio);
  EXPECT_EQ(config->button.line, defaults.button.line);
  const auto& p = config->calibrator.planner;
  EXPECT_EQ(p.waypoint_count, defaults.calibrator.planner.waypoint_count);
  EXPECT_EQ(p.margin_m, defaults.calibrator.planner.margin_m);
  EXPECT_EQ(p.z_max_m, defaults.calibrator.planner.z_max_m);
  EXPECT_EQ(p.max_tension_n, defaults.calibrator.planner.max_tension_n);
  EXPECT_EQ(config->calibrator.strategy, defaults.calibrator.strategy);
  EXPECT_EQ(config->calibrator.sequential.max_count, defaults.calibrator.sequential.max_count);
  EXPECT_EQ(config->calibrator.settle_timeout_us, defaults.calibrator.settle_timeout_us);
  EXPECT_EQ(config->calibrator.first_contact_timeout_us, defaults.calibrator.first_contact_timeout_us);
  EXPECT_EQ(config->calibrator.enable_timeout_us, defaults.calibrator.enable_timeout_us);
  EXPECT_EQ(config->calibrator.equilibrium.window_us, defaults.calibrator.equilibrium.window_us);
  EXPECT_EQ(config->calibrator.validation.max_anchor_change_m, defaults.calibrator.validation.max_anchor_change_m);
  EXPECT_EQ(config->solver.max_iterations, defaults.solver.max_iterations);
}

TEST(DaemonConfig, ReadsTheValuesGivenWithTheirUnits) {
  // GIVEN a configuration for the virtual robot
  const std::string text = R"(robot = "/tmp/robot.toml"
[control]
group = "robot-operators"
[loop]
period_ms = 10
[winches]
endpoint = "unix:/tmp/can.sock"
master_heartbeat_ms = 50
[winches.drive]
vendor_id = 0x9A
consumer_heartbeat_ms = 200
profile_velocity_mps = 1.5
[winches.encoder]
pdo_event_timer_ms = 5
[load_cell]
endpoint = "tcp:127.0.0.1:1502"
parity = "E"
preset = "flintec-ft-11"
decimals = 1
byte_order = "CDAB"
fault_timeout_ms = 400
[button]
kind = "none"
[equilibrium]
window_s = 1.5
[waypoints]
strategy = "sequential"
target_anchor_sigma = 0.01
target_offset_sigma = 0.015
max_count = 40
[limits]
first_contact_timeout_s = 0.5
[validation]
accept_max_iterations = true
)";
  // WHEN parsed
  const auto config = parse_daemon_config(test::with_endpoints(text), "vr.toml");
  // THEN the values are there in the daemon's units
  ASSERT_TRUE(config) << config.error().message();
  EXPECT_EQ(config->control_socket_group, "robot-operators");
  EXPECT_EQ(config->loop_period_us, 10'000);
  EXPECT_EQ(config->winches.endpoint, "unix:/tmp/can.sock");
  EXPECT_EQ(config->winches.master_heartbeat_us, 50'000);
  EXPECT_EQ(config->winches.drive.vendor_id, 0x9A);
  EXPECT_EQ(config->winches.drive.consumer_heartbeat_us, 200'000);
  EXPECT_EQ(config->winches.drive.profile_velocity_mps, 1.5);
  EXPECT_EQ(config->winches.encoder.pdo_event_timer_us, 5'000);
  EXPECT_EQ(config->load_cell.parity, 'E');
  // the preset's map, with the keys beside it overriding
  EXPECT_EQ(config->load_cell.preset, "flintec-ft-11");
  EXPECT_EQ(config->load_cell.map.value_type, drivers::modbus::ValueType::kInt32);
  EXPECT_EQ(config->load_cell.map.byte_order, drivers::modbus::ByteOrder::kCDAB);
  EXPECT_EQ(config->load_cell.map.decimals, 1);
  EXPECT_EQ(config->load_cell.map.unit, drivers::modbus::ForceUnit::kKilogram);
  EXPECT_EQ(config->load_cell.map.error.mask, 0x0002);
  EXPECT_FALSE(config->load_cell.map.error.active_when_set);
  EXPECT_EQ(config->load_cell.fault_timeout_us, 400'000);
  EXPECT_FALSE(config->button.gpio);
  EXPECT_EQ(config->calibrator.equilibrium.window_us, 1'500'000);
  EXPECT_EQ(config->calibrator.strategy, calibration::WaypointStrategy::kSequential);
  EXPECT_EQ(config->calibrator.sequential.target_anchor_sigma_m, 0.01);
  EXPECT_EQ(config->calibrator.sequential.target_offset_sigma_m, 0.015);
  EXPECT_EQ(config->calibrator.sequential.max_count, 40);
  EXPECT_EQ(config->calibrator.first_contact_timeout_us, 500'000);
  EXPECT_TRUE(config->calibrator.validation.accept_max_iterations);
}

TEST(DaemonConfig, RefusesBadInputNamingLineAndKey) {
  struct Case {
    std::string text;
    int line;
    std::string field;
  };
  const Case cases[] = {
      {"robot = \"r\"\n[loop]\nperiod_msec = 10\n", 3, "loop.period_msec"},               // unknown key
      {"robot = \"r\"\n[load_cell]\nslave_id = 300\n", 3, "load_cell.slave_id"},          // out of range
      {"robot = \"r\"\n[load_cell]\nslave_id = 0\n", 3, "load_cell.slave_id"},            // broadcast on RTU
      {"robot = \"r\"\n[load_cell]\nendpoint = \"tcp:h:502\"\nslave_id = 250\n", 4, "load_cell.slave_id"},
      {"robot = \"r\"\n[load_cell]\npreset = \"ft11\"\n", 3, "load_cell.preset"},         // unknown preset
      {"robot = \"r\"\n[load_cell]\nbyte_order = \"ADCB\"\n", 3, "load_cell.byte_order"},
      {"robot = \"r\"\n[load_cell]\nstatus_address = 1\n", 3, "load_cell.status_address"},  // overlaps the value
      {"robot = \"r\"\n[button]\nkind = \"gpoi\"\n", 3, "button.kind"},                    // not a choice
      {"robot = \"r\"\n[waypoints]\nstrategy = \"optimal\"\n", 3, "waypoints.strategy"},  // not a choice
      {"robot = \"r\"\n[waypoints]\nstrategy = \"sequential\"\nmax_count = 5\n", 4,
       "waypoints.max_count"},  // fewer than validation.min_samples
      {"robot = \"r\"\n[loop]\nperiod_ms = -5\n", 3, "loop.period_ms"},                    // not positive
      {"robot = \"r\"\n[button]\nactive_low = 1\n", 3, "button.active_low"},               // not a bool
      {"[store]\nstate_dir = \"/x\"\n", 0, "robot"},                                        // missing required
      {"robot = \"r\"\n[[winches.winch]]\ndrive_node_id = 1\n", 2, "winches.winch"},       // not 4 winches
      {"robot = \"r\"\n[control]\ngroup = \"robot operators\"\n", 3, "control.group"},   // not a group name
      {"robot = \"r\"\n[control]\ngroup = \"-x\"\n", 3, "control.group"},                // option-like name
      {"robot = \"r\"\n[control]\ngroup = 1000\n", 3, "control.group"},                    // not a string
      {"robot = \"r\"\n[control]\ngroup = \"\"\n", 3, "control.group"},                  // empty
      {"robot = \"r\"\n[winches.drive]\nquick_stop_option = 3\n", 3, "winches.drive.quick_stop_option"},
      {"robot = \"r\"\n[winches.drive]\nconsumer_heartbeat_ms = 100\n", 3,
       "winches.drive.consumer_heartbeat_ms"},  // not above the master's heartbeat period
      {"robot = \"r\"\n[winches.drive]\nvendor_id = -1\n", 3, "winches.drive.vendor_id"},
      {"robot = \"r\"\n[winches.drive]\neds = \"/nonexistent/epos4.eds\"\n", 3, "winches.drive.eds"},
      {"robot = \"r\"\n[[winches.winch]]\n[[winches.winch]]\n[[winches.winch]]\ndrive_eds = \"/nonexistent/x.eds\"\n"
       "[[winches.winch]]\n",
       5, "winches.winch[2].drive_eds"},  // the third winch's own EDS cannot be read
  };
  for (const Case& c : cases) {
    // GIVEN a configuration with one mistake WHEN parsed
    const auto config = parse_daemon_config(test::with_endpoints(c.text), "bad.toml");
    // THEN it is refused, naming the key (and its line where there is one)
    ASSERT_FALSE(config) << c.text;
    EXPECT_EQ(config.error().field, c.field) << config.error().message();
    if (c.line > 0) {
      EXPECT_EQ(config.error().line, c.line) << config.error().message();
    }
    EXPECT_EQ(config.error().file, "bad.toml");
  }
}

TEST(DaemonConfig, TheControlSocketGroupIsANameOrANumericId) {
  for (const std::string group : {"cdpr-operators", "robot_ops", "Ops.1", "machine$", "1001", "0"}) {
    // GIVEN [control] group set to a group name or id WHEN parsed
    const auto config = parse_daemon_config(test::config_text("[control]\ngroup = \"" + group + "\"\n"), "g.toml");
    // THEN it is taken as it is (whether it exists is checked when the socket is made)
    ASSERT_TRUE(config) << config.error().message();
    EXPECT_EQ(config->control_socket_group, group);
  }
  // AND a refusal says what a group must look like
  const auto refused = parse_daemon_config(test::config_text("[control]\ngroup = \"a:b\"\n"), "g.toml");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message().find("g.toml:3"), std::string::npos) << refused.error().message();
  EXPECT_NE(refused.error().message().find("group name"), std::string::npos) << refused.error().message();
}

}  // namespace
}  // namespace cdpr::daemon
