// calibctl as a script and an operator see it, the real program against a
// control socket served in this process: with --json every outcome, a
// failure too, is one JSON object on stdout; --json may follow the
// subcommand; a permission error names the group that may control the
// daemon instead of suggesting it is not running; show names the readings
// the committed fit rejected and its model warning.

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "calibctl/json_value.h"
#include "src/control/control_response.h"
#include "src/daemon/control_server.h"
#include "../text_contains.h"

namespace cdpr::integration {
namespace {

constexpr uid_t kNobody = 65534;

struct Outcome {
  int exit_status = -1;
  std::string out, err;
};

std::string file_text(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// A temporary directory others may enter (calibctl runs as nobody in one test).
class OpenDir {
 public:
  OpenDir() {
    char pattern[] = "/tmp/cdpr-calibctl-XXXXXX";
    path = mkdtemp(pattern);
    chmod(path.c_str(), 0755);
    // A copy others may run: the build tree need not be open to them.
    program = path + "/calibctl";
    std::filesystem::copy_file(std::string(CDPR_BINARY_DIR) + "/tools/calibctl/calibctl", program);
    chmod(program.c_str(), 0755);
  }
  ~OpenDir() { std::filesystem::remove_all(path); }

  // Runs calibctl with `args`, as `uid` when given (root only).
  Outcome calibctl(const std::vector<std::string>& args, uid_t uid = 0) const {
    const std::string out_path = path + "/out", err_path = path + "/err";
    const pid_t pid = fork();
    if (pid == 0) {
      const int out = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0666);
      const int err = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0666);
      dup2(out, 1);
      dup2(err, 2);
      if (uid != 0 && (setgid(uid) != 0 || setuid(uid) != 0)) _exit(125);
      std::vector<char*> argv{const_cast<char*>(program.c_str())};
      for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
      argv.push_back(nullptr);
      execv(program.c_str(), argv.data());
      _exit(126);
    }
    int status = 0;
    waitpid(pid, &status, 0);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, file_text(out_path), file_text(err_path)};
  }

  std::string path, program;
};

// What the daemon answers to show for a calibration that rejected two
// readings as gross errors and whose model does not fit.
std::string show_response() {
  store::CurrentCalibration current;
  current.seq = 3;
  Calibration& c = current.calibration;
  c.created = "2026-11-22T10:15:00Z";
  c.robot = "large";
  c.samples = 35;
  c.winches.resize(4);
  c.rejected = {{12, SensorKind::kEncoder, 3, -95.4}, {24, SensorKind::kForce, 0, 8.25}};
  c.model_warning = "the model does not fit the data: chi-square 912.3 for 614 degrees of freedom";
  return control::format_show_response(current);
}

// A control socket answering like the daemon, served on a thread.
class StubDaemon {
 public:
  explicit StubDaemon(const std::string& socket) {
    auto server = daemon::ControlServer::listen(socket, [](std::string_view line) -> std::string {
      if (line == "status") return std::string(kStatus) + "\n";
      if (line == "show") return show_response();
      // The request as the daemon received it (the test's paths need no JSON escapes).
      if (line.starts_with("start waypoints ")) return "{\"ok\":true,\"message\":\"" + std::string(line) + "\"}\n";
      return "{\"ok\":false,\"error\":\"abort ignored: no calibration running\"}\n";
    });
    EXPECT_TRUE(server.ok()) << server.status().to_string();
    server_ = std::move(server.value());
    thread_ = std::thread([this] {
      while (!stop_.load()) {
        std::vector<pollfd> fds;
        server_->append_poll_fds(fds);
        poll(fds.data(), fds.size(), 10);
        server_->service(fds);
      }
    });
  }
  ~StubDaemon() {
    stop_.store(true);
    thread_.join();
  }
  static constexpr const char* kStatus =
      "{\"ok\":true,\"state\":\"idle\",\"running\":false,\"waypoint\":0,\"waypoints\":0,\"samples\":0,"
      "\"skipped\":0,\"progress\":0,\"elapsed_s\":null,\"reason\":\"\",\"note\":\"\",\"detail\":\"\","
      "\"committed_seq\":0,\"interrupted\":\"\",\"store_problems\":[],\"pending_commit\":false}";

 private:
  std::unique_ptr<daemon::ControlServer> server_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

using ::cdpr::test::contains;

TEST(Calibctl, JsonBeforeOrAfterTheSubcommandPrintsTheDaemonsObject) {
  // GIVEN a daemon's control socket
  OpenDir dir;
  const std::string socket = dir.path + "/control";
  StubDaemon daemon(socket);
  for (const std::vector<std::string>& args : {std::vector<std::string>{"--socket", socket, "--json", "status"},
                                               {"--socket", socket, "status", "--json"},
                                               {"status", "--json", "--socket", socket}}) {
    // WHEN status is asked with --json in any place
    const Outcome outcome = dir.calibctl(args);
    // THEN the daemon's object is printed, exit 0
    EXPECT_EQ(outcome.exit_status, 0) << outcome.err;
    EXPECT_EQ(outcome.out, std::string(StubDaemon::kStatus) + "\n");
  }
}

TEST(Calibctl, AFailureWithJsonIsStillOneJsonObjectOnStdout) {
  OpenDir dir;
  const std::string socket = dir.path + "/control";
  // GIVEN no daemon WHEN status --json THEN an error object on stdout, the hint that it may not run, exit 2
  const Outcome none = dir.calibctl({"--socket", socket, "status", "--json"});
  EXPECT_EQ(none.exit_status, 2);
  EXPECT_EQ(none.out.substr(0, 31), "{\"ok\":false,\"error\":\"cannot con") << none.out;
  EXPECT_TRUE(contains(none.out, "No such file or directory (is cdpr-calibd running?)\"}\n")) << none.out;
  // AND GIVEN a daemon that refuses WHEN abort --json THEN its error object on stdout, exit 1
  StubDaemon daemon(socket);
  const Outcome refused = dir.calibctl({"--socket", socket, "abort", "--json"});
  EXPECT_EQ(refused.exit_status, 1);
  EXPECT_EQ(refused.out, "{\"ok\":false,\"error\":\"abort ignored: no calibration running\"}\n");
  // AND without --json stdout stays empty and stderr says it
  const Outcome text = dir.calibctl({"--socket", socket, "abort"});
  EXPECT_EQ(text.exit_status, 1);
  EXPECT_EQ(text.out, "");
  EXPECT_TRUE(contains(text.err, "abort ignored: no calibration running")) << text.err;
}

TEST(Calibctl, ShowNamesTheRejectedReadingsAndTheModelWarning) {
  // GIVEN a daemon whose committed calibration rejected two readings and warns of a misfit
  OpenDir dir;
  const std::string socket = dir.path + "/control";
  StubDaemon daemon(socket);
  // WHEN an operator asks show
  const Outcome text = dir.calibctl({"--socket", socket, "show"});
  // THEN the warning and each rejected reading (row, sensor, cable, residual) are printed after the fit
  EXPECT_EQ(text.exit_status, 0) << text.err;
  EXPECT_TRUE(contains(text.out, "\nMODEL WARNING: the model does not fit the data: chi-square 912.3 for 614 "
                                 "degrees of freedom\n"
                                 "gross errors (normalised residual at the robust fit; left out of the final fit):\n"
                                 "  row   12  encoder cable 3     -95.4 sigma\n"
                                 "  row   24  force                +8.2 sigma\n"))
      << text.out;
  // AND a script gets them from --json
  const Outcome json = dir.calibctl({"--socket", socket, "show", "--json"});
  EXPECT_EQ(json.exit_status, 0) << json.err;
  const auto shown = calibctl::JsonValue::parse(json.out);
  ASSERT_TRUE(shown) << json.out;
  EXPECT_EQ((*shown)["model_warning"].string().substr(0, 32), "the model does not fit the data:");
  const auto rejected = (*shown)["rejected"].array();
  ASSERT_EQ(rejected.size(), 2u) << json.out;
  EXPECT_EQ(rejected[1]["row"].integer(), 24);
  EXPECT_EQ(rejected[1]["sensor"].string(), "force");
  EXPECT_EQ(rejected[1]["cable"].integer(), 0);
  EXPECT_EQ(rejected[1]["residual"].number(), 8.25);
}

TEST(Calibctl, AResponseThatIsNotJsonIsRefusedWithoutACrash) {
  // GIVEN response lines a broken or hostile peer may send
  for (const std::string& text : std::vector<std::string>{"", "{", "{\"ok\":tru}", "[1,2", "\"\xff\"", "{\"ok\":1e400}",
                                 std::string(10'000, '['), "{\"ok\":true} trailing"}) {
    // WHEN parsed THEN refused with a reason, never thrown
    std::string error;
    EXPECT_FALSE(calibctl::JsonValue::parse(text, &error)) << text;
    EXPECT_FALSE(error.empty());
  }
  // AND members of the wrong kind read as blanks, not exceptions
  const auto odd = calibctl::JsonValue::parse(R"({"ok":"yes","seq":1e300,"state":7,"model":{"a":1},"fit":[1]})");
  ASSERT_TRUE(odd);
  EXPECT_FALSE((*odd)["ok"].boolean());
  EXPECT_EQ((*odd)["seq"].integer(), std::numeric_limits<int>::max());
  EXPECT_EQ((*odd)["state"].string(), "");
  EXPECT_TRUE((*odd)["model"].array().empty());
  EXPECT_TRUE((*odd)["fit"]["cost_final"].is_null());
  EXPECT_TRUE((*odd)["missing"]["deeper"].is_null());
}

TEST(Calibctl, APermissionErrorNamesTheGroupNotAMissingDaemon) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to run calibctl as another user";
  // GIVEN a daemon's socket, mode 0660, group root, in a directory others may enter
  OpenDir dir;
  const std::string socket = dir.path + "/control";
  StubDaemon daemon(socket);
  ASSERT_EQ(chown(socket.c_str(), 0, 0), 0);
  // WHEN a user outside the group asks for status (with --json)
  const Outcome outcome = dir.calibctl({"--socket", socket, "status", "--json"}, kNobody);
  // THEN it says permission denied and which group may control the daemon, not that it may not run
  EXPECT_EQ(outcome.exit_status, 2);
  EXPECT_TRUE(contains(outcome.err, "permission denied: only members of group 'root' may control cdpr-calibd"))
      << outcome.err;
  EXPECT_FALSE(contains(outcome.err, "is cdpr-calibd running")) << outcome.err;
  EXPECT_TRUE(contains(outcome.out, "{\"ok\":false,\"error\":\"cannot connect to " + socket + ": permission denied"))
      << outcome.out;
  // AND WHEN the socket's directory is closed to them THEN it says that
  chmod(dir.path.c_str(), 0711);
  const std::string inner = dir.path + "/closed";
  mkdir(inner.c_str(), 0700);
  StubDaemon closed(inner + "/control");
  const Outcome hidden = dir.calibctl({"--socket", inner + "/control", "status"}, kNobody);
  EXPECT_EQ(hidden.exit_status, 2);
  EXPECT_TRUE(contains(hidden.err, "permission denied: its directory is closed to you")) << hidden.err;
}

TEST(Calibctl, StartWithWaypointsSendsTheFilesAbsolutePathAndTheRun) {
  // GIVEN a daemon's control socket
  OpenDir dir;
  const std::string socket = dir.path + "/control";
  StubDaemon daemon(socket);
  // WHEN started with a relative waypoints path and a run to append to
  const Outcome outcome = dir.calibctl({"--socket", socket, "start", "--waypoints", "d/waypoints.csv", "--append-to",
                                        "run-000007"});
  // THEN the daemon gets the path made absolute (it does not share calibctl's directory) and the run
  EXPECT_EQ(outcome.exit_status, 0) << outcome.err;
  EXPECT_EQ(outcome.out, "start waypoints " + std::filesystem::current_path().string() +
                             "/d/waypoints.csv run-000007\n");
  // AND a path the request cannot carry (a blank) is refused by calibctl, exit 1; --append-to alone is an error
  const Outcome blank = dir.calibctl({"--socket", socket, "start", "--waypoints", "/srv/my waypoints.csv"});
  EXPECT_EQ(blank.exit_status, 1);
  EXPECT_TRUE(contains(blank.err, "the path must not contain blanks")) << blank.err;
  EXPECT_NE(dir.calibctl({"--socket", socket, "start", "--append-to", "7"}).exit_status, 0);
}

}  // namespace
}  // namespace cdpr::integration
