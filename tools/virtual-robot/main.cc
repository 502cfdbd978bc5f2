// virtual-robot: a simulated cable robot speaking the real protocols (CAN
// frames over a Unix socket, Modbus TCP, pose stream) with physics from the
// simulator, for running cdpr-calibd without hardware (make demo, tests).
// Runs until SIGTERM or SIGINT.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>

#include <CLI/CLI.hpp>

#include "virtual-robot/virtual_robot.h"
#include "version/version.h"

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop.store(true); }

}  // namespace

int main(int argc, char** argv) {
  using cdpr::virtual_robot::VirtualRobotOptions;
  CLI::App app{"virtual-robot: a simulated cable robot (true heavy-cable equilibrium, lightly damped sway, "
               "sensor noise of the preset, optional hidden effects) serving CANopen over a Unix socket, a Modbus TCP or RTU load cell and a "
               "pose stream; writes robot.toml (nominal), truth.toml and 'ready' into --endpoints"};
  app.set_version_flag("--version", cdpr::version::version_text("virtual-robot"));
  VirtualRobotOptions options;
  std::string preset = "large";
  app.add_option("--preset", preset, "robot of the paper's Table I: large or small")
      ->check(CLI::IsMember({"large", "small"}))->capture_default_str();
  app.add_option("--seed", options.seed, "true encoder offsets, nominal anchor perturbation, sensor noise")
      ->capture_default_str();
  app.add_option("--time-scale", options.time_scale, "simulated seconds per real second (drive speed, settling)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--endpoints,--dir", options.dir,
                 "directory for can.sock, pose.sock, clock (the robot's clock: cdpr-calibd --sim-clock), robot.toml, truth.toml, "
                 "drive.eds and encoder.eds (what its CANopen nodes play) and ready (created)")->required();
  app.add_option("--modbus-port", options.modbus_port, "Modbus TCP port on 127.0.0.1; 0: any free port (see ready)")
      ->check(CLI::Range(0, 65535))->capture_default_str();
  std::string transport = "tcp";
  app.add_option("--modbus-transport", transport,
                 "load cell on Modbus TCP (127.0.0.1:--modbus-port) or RTU (a pty linked as <endpoints>/load_cell.tty)")
      ->check(CLI::IsMember({"tcp", "rtu"}))->capture_default_str();
  std::string model = "legacy-float32";
  app.add_option("--load-cell-model", model,
                 "register map: legacy-float32 (float32 N), flintec-ft-11 or laumas-tlu (kg, 2 decimals; "
                 "docs/fieldbus.md)")
      ->check(CLI::IsMember({"legacy-float32", "flintec-ft-11", "laumas-tlu"}))->capture_default_str();
  app.add_option("--modbus-unit-id", options.load_cell.unit_id,
                 "the load cell's unit identifier; requests for others get no answer (RTU) or exception 0x0B (TCP)")
      ->check(CLI::Range(1, 247))->capture_default_str();
  double latency_ms = 0.0;
  app.add_option("--modbus-latency-ms", latency_ms, "reply latency of the load cell [ms, real time]")
      ->check(CLI::Range(0.0, 10'000.0))->capture_default_str();
  app.add_option("--anchor-perturbation", options.anchor_perturbation_m,
                 "robot.toml's nominal anchors = true anchors + a random vector of this norm [m]")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--noise-scale", options.noise_scale, "multiplies every sensor sigma of the preset; 0: noiseless")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--damping-ratio", options.physics.damping_ratio,
                 "damping ratio of the platform's sway after a move (0: none, 0.05: light)")
      ->check(CLI::Range(0.0, 0.99))->capture_default_str();
  app.add_option("--sway-period", options.physics.sway_period_s,
                 "sway period [s, simulated]; 0: from the cable geometry (several seconds on the large robot)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--winch-speed", options.physics.winch_speed_mps, "drive profile velocity [m/s, simulated]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--pose-rate", options.pose_rate_hz, "pose stream rate [Hz, real time]")
      ->check(CLI::Range(1.0, 1000.0))->capture_default_str();
  app.add_option("--axial-stiffness", options.effects.axial_stiffness_n,
                 "hidden elasticity: cable EA [N] (default inextensible); the encoders count unstretched cable")
      ->check(CLI::PositiveNumber);
  app.add_option("--force-bias", options.effects.force_bias_n,
                 "hidden load-cell bias b [N]: reading = (1 + g) * tension + b");
  app.add_option("--force-gain", options.effects.force_gain, "hidden load-cell gain error g")
      ->check(CLI::Range(-0.9, 10.0));
  std::string quirks = "none";
  app.add_option("--canopen-quirks", quirks,
                 "vendor quirk profile the CANopen nodes play, each a shipped EDS file: two-tpdo-encoder (encoders), "
                 "rtr-bit30, no-type-255 or rpm-units (drives; rpm: drum 0.2 m, gear 10, the daemon needs "
                 "[winches.mechanics]); an encoder's and a drive's comma-separated; docs/fieldbus.md")
      ->check([](const std::string& names) {
        std::string error;
        return cdpr::virtual_robot::parse_canopen_quirks(names, error) ? std::string() : error;
      })
      ->capture_default_str();
  std::string drive_eds, encoder_eds;
  app.add_option("--drive-eds", drive_eds, "the EDS file the drives play instead (their object dictionary)");
  app.add_option("--encoder-eds", encoder_eds, "the EDS file the encoders play instead");
  app.add_flag("--operate", options.operation.enabled,
               "in operation: the robot's own controller commissions and enables the drives and moves the platform "
               "by itself, random point-to-point moves (drawn from --seed) with rests between; a daemon may only "
               "listen ([operation] watch = true, docs/operation.md)");
  app.add_option("--rest-min", options.operation.rest_min_s, "operation: shortest rest after a move [s, simulated]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--rest-max", options.operation.rest_max_s, "operation: longest rest after a move [s, simulated]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--job-speed", options.operation.winch_speed_mps,
                 "operation: the longest cable's speed in a move [m/s, simulated]")
      ->check(CLI::PositiveNumber)->capture_default_str();
  std::vector<std::string> injections;
  app.add_option("--inject", injections,
                 "a fault at a robot time T [s, simulated, since start] (repeatable): slip@T:cable=i,size=METRES "
                 "(encoder i reads that much more), anchor@T:cable=i,dx=..,dy=..,dz=.. (pulley exit moved [m]), "
                 "creep@T:cable=i,rate=M_PER_S (the cable lengthens, same reading), payload@T:mass=KG (added)")
      ->check([](const std::string& text) {
        std::string why;
        return cdpr::virtual_robot::parse_operation_fault(text, why) ? std::string() : why;
      });
  app.add_option("--frame-log", options.frame_log_path,
                 "log every CAN frame a bus client (the daemon) sends, one line each: robot clock [us], id, length, data")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  std::string eds_error;
  cdpr::virtual_robot::CanopenNodes::apply(*cdpr::virtual_robot::parse_canopen_quirks(quirks, eds_error), options.nodes);
  if (!drive_eds.empty()) options.nodes.drive_eds = cdpr::virtual_robot::read_device_eds(drive_eds, eds_error);
  if (!encoder_eds.empty()) options.nodes.encoder_eds = cdpr::virtual_robot::read_device_eds(encoder_eds, eds_error);
  if (!eds_error.empty()) {
    std::fprintf(stderr, "virtual-robot: %s\n", eds_error.c_str());
    return 1;
  }
  for (const std::string& text : injections) {
    std::string why;
    options.faults.push_back(*cdpr::virtual_robot::parse_operation_fault(text, why));
  }
  if (options.operation.rest_max_s < options.operation.rest_min_s) {
    std::fprintf(stderr, "virtual-robot: --rest-max must be at least --rest-min\n");
    return 1;
  }
  if (options.operation.enabled && quirks.find("rpm-units") != std::string::npos) {
    std::fprintf(stderr, "virtual-robot: --operate drives the profiles in increments per second: not with rpm-units\n");
    return 1;
  }
  options.preset = *cdpr::sim::parse_preset(preset);
  options.report_stops = true;  // a line per stop: how far the platform swung (docs/fieldbus.md)
  options.modbus_rtu = transport == "rtu";
  options.load_cell.model = *cdpr::virtual_robot::parse_load_cell_model(model);
  options.load_cell.reply_latency_us = static_cast<cdpr::hal::TimeUs>(latency_ms * 1000.0);

  std::error_code error;
  std::filesystem::create_directories(options.dir, error);
  auto robot = cdpr::virtual_robot::VirtualRobot::create(options);
  if (!robot) {
    std::fprintf(stderr, "virtual-robot: %s\n", robot.error().c_str());
    return 1;
  }
  std::signal(SIGTERM, on_signal);
  std::signal(SIGINT, on_signal);
  std::printf("virtual-robot: %s preset, seed %llu, time x%g; CAN %s, load cell %s, pose %s\n", preset.c_str(),
              static_cast<unsigned long long>(options.seed), options.time_scale, (*robot)->can_endpoint().c_str(),
              (*robot)->modbus_endpoint().c_str(), (*robot)->pose_endpoint().c_str());
  std::fflush(stdout);
  (*robot)->run(g_stop);
  if (const auto& stop = (*robot)->stops().latest(); stop && !stop->settled && !stop->interrupted) {
    std::printf("virtual-robot: stop at %.1f s (robot time), platform at %.2f m/s: platform up to %.2f m from where "
                "the stop began (%.1f s after it), still swinging %.2f m from it at exit\n",
                stop->began_s, stop->speed_mps, stop->largest_m, stop->largest_at_s - stop->began_s,
                stop->from_start_m);
  }
  cdpr::hal::TimeUs heartbeat_gap_us = 0;
  for (int winch = 0; winch < cdpr::kCableCount; ++winch) {
    heartbeat_gap_us = std::max(heartbeat_gap_us, (*robot)->nodes().drive(winch).longest_consumer_gap_us());
  }
  std::printf("virtual-robot: stopped (%d equilibrium solves failed, %d with a slack cable; %.1f s of robot time "
              "not simulated while starved of CPU; longest gap between the master's heartbeats %.0f ms)\n",
              (*robot)->physics().failed_solves(), (*robot)->physics().slack_solves(), (*robot)->robot_time_lost_s(),
              1e-3 * static_cast<double>(heartbeat_gap_us));
  if (const cdpr::virtual_robot::ProductionController* controller = (*robot)->controller()) {
    std::printf("virtual-robot: in operation: %d moves, %d rests, %d targets unreachable\n", controller->moves(),
                controller->rests(), controller->unreachable());
  }
  std::printf("virtual-robot: %llu CAN frames received from the bus's clients\n",
              static_cast<unsigned long long>((*robot)->frames_from_clients()));
  return 0;
}
