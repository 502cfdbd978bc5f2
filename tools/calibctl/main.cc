// calibctl: the operator's client of cdpr-calibd's control socket. Starts
// (planned, or through a waypoints file) and aborts a field calibration,
// shows its progress, the current calibration, the stored versions, rolls back to one of them, retries a commit that
// failed, and commits a kept run refitted with an extra model term.
//
// Exit status: 0 done; 1 the daemon refused the request (or, with
// status --follow, the run failed); 2 no daemon, or a broken connection.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>

#include "calibctl/control_client.h"
#include "calibctl/json_value.h"
#include "calibctl/render.h"
#include "src/control/protocol_answer.h"
#include "version/version.h"

namespace {

using cdpr::calibctl::ControlClient;
using cdpr::calibctl::JsonValue;

constexpr int kExitRefused = 1;
constexpr int kExitNoDaemon = 2;

struct Options {
  std::string socket_path = "/run/cdpr-calib/control";
  bool json = false;
  bool follow = false;
  int interval_ms = 500;
  int seq = 0;
  bool report_path = false;
  std::string with_term;  // commit --with-term
  std::string run;        // its run: 7 or run-000007; empty: the newest
  std::string waypoints;  // start --waypoints
  std::string append_to;  // start --append-to RUN
};

// `start` or `start waypoints <absolute path> [<run>]` (src/control/control_request.h):
// the daemon does not share the client's working directory. Empty with
// `error` set when the path cannot be sent (a blank or control byte in it).
std::string start_request(const Options& options, std::string& error) {
  if (options.waypoints.empty()) return "start";
  std::error_code ignored;
  std::filesystem::path path = std::filesystem::absolute(options.waypoints, ignored);
  const std::string text = path.lexically_normal().string();
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (u <= 0x20 || u >= 0x7f) {
      error = "--waypoints " + options.waypoints + ": the path must not contain blanks or non-ASCII bytes";
      return {};
    }
  }
  return "start waypoints " + text + (options.append_to.empty() ? "" : " " + options.append_to);
}

// A failure: on stderr for the operator and, with --json, on stdout as one
// JSON object ({"ok":false,"error":...}, the daemon's own when it refused),
// so that a script always reads one object.
void report_failure(bool json, const std::string& error, const std::string& daemon_response = {}) {
  std::fprintf(stderr, "calibctl: %s\n", error.c_str());
  if (!json) return;
  const std::string object =
      daemon_response.empty() ? cdpr::control::format_error_response(error) : daemon_response + "\n";
  std::fputs(object.c_str(), stdout);
}

// Sends one request; reports the failure and returns nullopt when it fails.
// `raw` receives the response line as the daemon sent it.
std::optional<JsonValue> ask(ControlClient& client, const std::string& request, bool json, int& exit_code,
                             std::string& raw) {
  std::string& response = raw;
  std::string error;
  if (!client.request(request, response, error)) {
    report_failure(json, error);
    exit_code = kExitNoDaemon;
    return std::nullopt;
  }
  auto value = JsonValue::parse(response, &error);
  if (!value) {
    report_failure(json, "unreadable response (" + error + "): " + response);
    exit_code = kExitNoDaemon;
    return std::nullopt;
  }
  if (!(*value)["ok"].boolean()) {
    report_failure(json, request + ": " + (*value)["error"].string(), response);
    exit_code = kExitRefused;
    return std::nullopt;
  }
  return value;
}

// After `refit`: polls status until the refit has ended, prints its outcome;
// exit 1 unless it was committed.
int wait_for_refit(ControlClient& client, const Options& options) {
  int exit_code = 0;
  for (;;) {
    std::string raw;
    const auto status = ask(client, "status", options.json, exit_code, raw);
    if (!status) return exit_code;
    const JsonValue refit = (*status)["refit"];
    if (refit.is_null() || refit["state"].string() != "running") {
      if (options.json) {
        std::printf("%s\n", raw.c_str());
      } else {
        std::printf("%s", cdpr::calibctl::render_refit(refit).c_str());
      }
      return !refit.is_null() && refit["state"].string() == "committed" ? 0 : kExitRefused;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(options.interval_ms));
  }
}

// Polls status until the run is over; prints a line whenever it changes.
int follow(ControlClient& client, const Options& options) {
  std::string last;
  int exit_code = 0;
  for (;;) {
    std::string raw;
    const auto status = ask(client, "status", options.json, exit_code, raw);
    if (!status) return exit_code;
    const std::string line = options.json ? raw : cdpr::calibctl::render_progress(*status);
    if (line != last) {
      std::printf("%s\n", line.c_str());
      std::fflush(stdout);
      last = line;
    }
    if (!(*status)["running"].boolean()) {
      if (!options.json) std::printf("%s", cdpr::calibctl::render_status(*status).c_str());
      const std::string state = (*status)["state"].string();
      return state == "failed" || state == "aborted" ? kExitRefused : 0;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(options.interval_ms));
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"calibctl: control the cable-robot self-calibration daemon (cdpr-calibd) through its control socket"};
  app.set_version_flag("--version", cdpr::version::version_text("calibctl"));
  Options options;
  if (const char* env = std::getenv("CDPR_CALIB_SOCKET")) options.socket_path = env;
  app.add_option("--socket", options.socket_path, "the daemon's control socket (env CDPR_CALIB_SOCKET)")
      ->capture_default_str();
  app.add_flag("--json", options.json,
               "print the daemon's JSON response instead of text (a failure too, as {\"ok\":false,\"error\":...})");
  app.require_subcommand(1);
  // Options of calibctl itself are accepted after the subcommand too (`status --json`).
  app.fallthrough();
  auto* start = app.add_subcommand("start", "start a field calibration (as the button does)");
  start->add_flag("--follow,-f", options.follow, "then show progress until the run ends");
  start->add_option("--waypoints", options.waypoints,
                    "drive exactly the waypoints of this waypoints.csv (as cdpr-calib diagnose writes it) "
                    "instead of a plan; the daemon reads the file and checks every waypoint first");
  start->add_option("--append-to", options.append_to,
                    "with --waypoints: the run's data are this kept run's samples (7 or run-000007) followed by "
                    "the new poses, so that diagnose sees them together")
      ->needs("--waypoints");
  app.add_subcommand("abort", "abort the calibration in progress (winches halted, old calibration kept)");
  auto* status = app.add_subcommand("status", "state, waypoint k/N, progress and reasons");
  status->add_flag("--follow,-f", options.follow, "show progress until the run ends (exit 1 if it fails)");
  status->add_option("--interval", options.interval_ms, "poll interval of --follow [ms]")
      ->check(CLI::Range(50, 60'000))->capture_default_str();
  auto* show = app.add_subcommand("show", "the current calibration");
  show->add_flag("--report", options.report_path,
                 "print only the path of its report.html (in its run's history entry); exit 1 when it has none");
  app.add_subcommand("history", "the stored calibrations, newest first (* = current)");
  auto* commit = app.add_subcommand(
      "commit",
      "commit the calibration a failed commit kept in <state>/pending, once its cause is fixed; with --with-term: "
      "refit a kept run's samples with the catenary plus model terms and commit that fit when it validates");
  commit->add_option("--with-term", options.with_term,
                     "model terms to add to the catenary, comma-separated (e.g. load_cell_bias, as the model check "
                     "of the run names them); waits for the refit and prints its outcome (exit 1 unless committed)");
  commit->add_option("run", options.run, "with --with-term: the run to refit (7 or run-000007; default: the newest)");
  commit->add_option("--interval", options.interval_ms, "poll interval while waiting for the refit [ms]")
      ->check(CLI::Range(50, 60'000))->capture_default_str();
  app.add_subcommand("reset-faults", "clear the devices' latched faults once their cause is fixed (not during a run)");
  auto* rollback = app.add_subcommand("rollback", "make stored calibration SEQ current again");
  rollback->add_option("seq", options.seq, "sequence number (see history)")->required()->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  const std::string command = app.get_subcommands().front()->get_name();
  ControlClient client;
  std::string error;
  if (!client.connect(options.socket_path, error)) {
    report_failure(options.json, error);
    return kExitNoDaemon;
  }
  if (command == "commit" && options.with_term.empty() && !options.run.empty()) {
    report_failure(options.json, "commit RUN needs --with-term NAME (a run is only refitted with a term)");
    return kExitRefused;
  }
  const bool refit = command == "commit" && !options.with_term.empty();
  std::string request = command == "rollback" ? "rollback " + std::to_string(options.seq) : command;
  if (command == "start") request = start_request(options, error);
  if (request.empty()) {
    report_failure(options.json, error);
    return kExitRefused;
  }
  if (refit) request = "refit " + options.with_term + (options.run.empty() ? "" : " " + options.run);
  int exit_code = 0;
  if (command == "status" && options.follow) return follow(client, options);
  std::string raw;
  const auto response = ask(client, request, options.json, exit_code, raw);
  if (!response) return exit_code;
  using namespace cdpr::calibctl;
  if (refit) {
    if (!options.json) std::printf("%s\n", (*response)["message"].string().c_str());
    return wait_for_refit(client, options);
  }
  if (options.json) {
    std::printf("%s\n", raw.c_str());
  } else if (command == "status") {
    std::printf("%s", render_status(*response).c_str());
  } else if (command == "show" && options.report_path) {
    const JsonValue run = (*response)["run"];
    if (run.is_null() || run["report"].is_null()) {
      report_failure(false, "the current calibration has no report (none committed, or committed by an older daemon)");
      return kExitRefused;
    }
    std::printf("%s\n", run["report"].string().c_str());
  } else if (command == "show") {
    std::printf("%s", render_show(*response).c_str());
  } else if (command == "history") {
    std::printf("%s", render_history(*response).c_str());
  } else {
    std::printf("%s\n", (*response)["message"].string().c_str());
    if (command == "start" && options.follow) return follow(client, options);
  }
  return 0;
}
