// cdpr-calibd: the field self-calibration daemon of a cable robot
// (docs/DESIGN.md). main() alone chooses the drivers for the hal interfaces
// from the configuration, then hands everything to the event loop
// (src/daemon/daemon_loop.h).
//
// Runs under systemd (Type=notify: READY, STATUS, WATCHDOG via libsystemd)
// or in the foreground (without NOTIFY_SOCKET the notifications are no-ops).
// SIGTERM or SIGINT: the winches are stopped and the daemon exits 0.
// Startup failures (bad configuration, robot.toml, state directory, another
// instance holding the state directory's lock, control socket) exit 1 so
// systemd can restart it; a device that is not there yet is not a startup
// failure (the loop reconnects, and preflight refuses to calibrate without
// it).
#include <sys/uio.h>
#include <systemd/sd-daemon.h>
#include <systemd/sd-journal.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <sstream>
#include <vector>
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "drivers/can/canopen_winch_bank.h"
#include "drivers/can/listening_winch_bank.h"
#include "drivers/clock/monotonic_clock.h"
#include "drivers/clock/shared_clock.h"
#include "drivers/common/load_cell_reader.h"
#include "drivers/modbus/modbus_load_cell.h"
#include "drivers/pose/pose_stream_source.h"
#ifdef CDPR_HAVE_GPIOD
#include "drivers/button/gpio_button.h"
#endif
#include "src/daemon/daemon_config.h"
#include "src/daemon/daemon_loop.h"
#include "src/daemon/instance_lock.h"
#include "src/formats/robot_toml.h"
#include "version/version.h"

namespace {

using namespace cdpr;

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop.store(true); }

// A line whose tail after " | " is KEY=value words (watch mode's finding,
// src/daemon/watch_service.cc) goes to the journal with those as its
// fields when stderr is the journal (JOURNAL_STREAM); the text before is
// the MESSAGE. Anything else, and outside systemd, is a plain stderr line.
bool journal_with_fields(const std::string& text) {
  const std::size_t bar = text.find(" | ");
  if (bar == std::string::npos || std::getenv("JOURNAL_STREAM") == nullptr) return false;
  std::vector<std::string> fields{"MESSAGE=cdpr-calibd: " + text.substr(0, bar), "SYSLOG_IDENTIFIER=cdpr-calibd"};
  std::istringstream words(text.substr(bar + 3));
  for (std::string word; words >> word;) {
    if (word.find('=') == std::string::npos) return false;
    fields.push_back(word);
  }
  std::vector<iovec> vectors;
  for (std::string& field : fields) vectors.push_back({field.data(), field.size()});
  return sd_journal_sendv(vectors.data(), static_cast<int>(vectors.size())) >= 0;
}

void log_line(const std::string& text) {
  if (journal_with_fields(text)) return;
  std::fprintf(stderr, "cdpr-calibd: %s\n", text.c_str());
  std::fflush(stderr);
}

// sd_notify(3). Pings the watchdog at half its interval, as sd_watchdog_enabled(3) advises.
class SdNotifier final : public daemon::ServiceNotifier {
 public:
  explicit SdNotifier(const hal::Clock& clock) : clock_(clock) {
    std::uint64_t interval_us = 0;
    if (sd_watchdog_enabled(0, &interval_us) > 0) ping_interval_us_ = static_cast<hal::TimeUs>(interval_us / 2);
  }
  void ready() override { sd_notify(0, "READY=1"); }
  void status(const std::string& text) override { sd_notify(0, ("STATUS=" + text).c_str()); }
  void watchdog() override {
    if (ping_interval_us_ <= 0) return;
    const hal::TimeUs now_us = clock_.now_us();
    if (now_us - last_ping_us_ < ping_interval_us_) return;
    last_ping_us_ = now_us;
    sd_notify(0, "WATCHDOG=1");
  }
  void stopping() override { sd_notify(0, "STOPPING=1"); }

 private:
  const hal::Clock& clock_;
  hal::TimeUs ping_interval_us_ = 0;  // 0: no watchdog configured
  hal::TimeUs last_ping_us_ = 0;
};

std::unique_ptr<hal::Button> open_button(const daemon::ButtonConfig& c) {
  if (!c.gpio) return nullptr;
#ifdef CDPR_HAVE_GPIOD
  auto button = drivers::button::GpioButton::open({c.chip, static_cast<unsigned>(c.line), c.active_low, c.debounce_us});
  if (!button.ok()) {
    log_line("button: " + button.status().to_string() + "; starting only from the control socket");
    return nullptr;
  }
  return std::move(button.value());
#else
  log_line("button: built without libgpiod; starting only from the control socket");
  return nullptr;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdpr-calibd: field self-calibration daemon of a cable-driven parallel robot"};
  app.set_version_flag("--version", cdpr::version::version_text("cdpr-calibd"));
  std::string config_path = "/etc/cdpr-calib/cdpr-calibd.toml";
  app.add_option("--config,-c", config_path, "configuration file (keys: see the example cdpr-calibd.toml)")
      ->capture_default_str();
  std::string sim_clock_path;
  app.add_option("--sim-clock", sim_clock_path,
                 "take time from a simulator's clock file (the virtual robot's <endpoints>/clock) instead of "
                 "CLOCK_MONOTONIC, as ROS's use_sim_time: every timeout then counts the simulated robot's time. "
                 "For tests and demos against the virtual robot, never on a robot");
  CLI11_PARSE(app, argc, argv);

  const auto config = daemon::read_daemon_config(config_path);
  if (!config) {
    log_line("configuration: " + config.error().message());
    return 1;
  }
  if (const auto problem = daemon::check_config_paths(*config)) {
    log_line("configuration: " + problem->message());
    return 1;
  }
  for (const daemon::UnsafeValue& unsafe : config->unsafe_accepted) {
    log_line("configuration: " + config->source + ":" + std::to_string(unsafe.line) + ": " + unsafe.key + ": " +
             unsafe.reason + " (accepted: unsafe_ok)");
  }
  const auto robot = formats::read_robot_toml(config->robot_path);
  if (!robot) {
    log_line("robot: " + robot.error().message());
    return 1;
  }
  if (const auto problem = daemon::check_config_against_robot(*config, *robot)) {
    log_line("configuration: " + problem->message());
    return 1;
  }
  drivers::can::CanWinchBankConfig winch_config = config->winches;
  winch_config.last_positions_path = config->store.state_dir + "/winch-positions";  // survives a restart
  const drivers::modbus::ModbusLoadCellConfig& cell_config = config->load_cell;
  for (const std::string& problem : {drivers::can::validate(winch_config), drivers::modbus::validate(cell_config)}) {
    if (!problem.empty()) {
      log_line("configuration " + config_path + ": " + problem);
      return 1;
    }
  }

  // Before the store is touched (open() removes temp files) and the control
  // socket bound: a second instance must change nothing of the first's.
  const auto lock = daemon::InstanceLock::acquire(config->store.state_dir);
  if (!lock.ok()) {
    log_line(lock.status().to_string());
    return 1;
  }
  store::CalibrationStore store(config->store);
  if (const auto opened = store.open(); !opened) {
    log_line("store: " + opened.error().message());
    return 1;
  }

  // The loop, the devices' time stamps and every timeout run on `clock`; the
  // systemd watchdog stays on the monotonic clock, which systemd watches.
  drivers::MonotonicClock monotonic_clock;
  std::unique_ptr<drivers::SharedClock> sim_clock;
  if (!sim_clock_path.empty()) {
    hal::Status opened;
    sim_clock = drivers::SharedClock::open(sim_clock_path, opened);
    if (!sim_clock) {
      log_line("--sim-clock: " + opened.to_string());
      return 1;
    }
    log_line("time from the simulator's clock " + sim_clock_path + " (--sim-clock)");
  }
  const hal::Clock& clock = sim_clock ? static_cast<const hal::Clock&>(*sim_clock) : monotonic_clock;
  drivers::can::CanopenWinchBank winches(winch_config, drivers::can::make_can_connector(config->winches.endpoint));
  if (!winches.setup_error().empty()) {
    log_line("configuration " + config_path + ": winches: " + winches.setup_error());
    return 1;
  }
  if (const std::string plain = winches.nodes_without_eds(); !plain.empty()) {
    log_line("winches: no EDS for " + plain + " ([winches.drive] / [winches.encoder] eds): configured with the CiA "
             "402/406 defaults (4 PDOs, transmission type 255, increments per second unless 0x60A9 says otherwise)");
  }
  // Watch mode: the robot's controller owns the bus; the daemon only listens (docs/operation.md).
  drivers::can::ListeningWinchBank listener(winch_config, config->operation.listen,
                                            drivers::can::make_can_connector(config->winches.endpoint));
  hal::WinchBank& bank = config->operation.watch ? static_cast<hal::WinchBank&>(listener) : winches;
  if (config->operation.watch) log_line("watch mode: listening on the CAN bus, sending nothing");
  drivers::modbus::ModbusLoadCell modbus_load_cell(cell_config, clock);
  // The Modbus transaction (up to response timeout x tries) runs on the
  // reader's thread, never in the 20 ms loop.
  drivers::LoadCellReader load_cell(modbus_load_cell, clock,
                                    {config->load_cell.poll_interval_us, config->load_cell.fault_timeout_us,
                                     daemon::DaemonLoop::kReconnectIntervalUs});
  drivers::pose::PoseStreamSource pose(config->pose.endpoint, clock, config->pose.connect_timeout_us);
  const std::unique_ptr<hal::Button> button = open_button(config->button);

  struct sigaction action {};
  action.sa_handler = on_signal;  // no SA_RESTART: poll() returns EINTR at once
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  SdNotifier notifier(monotonic_clock);
  daemon::DaemonLoop loop(*config, *robot, {bank, load_cell, pose, button.get()}, store, clock, notifier, log_line);
  if (const hal::Status started = loop.start(); !started.ok()) {
    log_line(started.to_string());
    return 1;
  }
  log_line("ready: robot " + robot->name + ", control socket " + config->control_socket + ", state " +
           config->store.state_dir);
  loop.run(g_stop);
  return 0;
}
