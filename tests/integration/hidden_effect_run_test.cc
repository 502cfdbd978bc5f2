// The daemon against a virtual robot that hides an effect robot.toml does
// not describe, as tools/demo.sh runs it (large preset, time scale 20,
// nominal anchors 0.3 m off, the shipped equilibrium thresholds): the run's
// samples stay in its history entry, the model check after the solve names
// the effect in `calibctl status` (and `show` when the fit was committed),
// and `cdpr-calib diagnose` on the entry names the same one.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "virtual_robot_process.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

std::string read_text(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

int data_rows(const std::string& samples_csv) {
  std::ifstream file(samples_csv);
  std::string line;
  int rows = 0;
  while (std::getline(file, line)) rows += !line.empty() && line[0] != '#' && line.rfind("id,", 0) != 0;
  return rows;
}

// The value after `key=` on diagnose's `summary:` line ("" when absent).
std::string summary_value(const std::string& output, const std::string& key) {
  const std::size_t line = output.find("\nsummary: ");
  if (line == std::string::npos) return {};
  const std::size_t at = output.find(" " + key + "=", line);
  if (at == std::string::npos) return {};
  const std::size_t begin = at + key.size() + 2;
  return output.substr(begin, output.find_first_of(" \n", begin) - begin);
}

// One whole daemon run on a robot with `effect_options`; checks that the
// model check and diagnose both add `effect` (a model term name) and no
// structure remains.
void expect_effect_named(const std::vector<std::string>& effect_options, const std::string& effect) {
  // GIVEN the virtual large robot with a hidden effect, as the demo runs it
  std::vector<std::string> robot_options{"--anchor-perturbation", "0.3"};
  robot_options.insert(robot_options.end(), effect_options.begin(), effect_options.end());
  VirtualRobotProcess rig("large", 20, "", robot_options);
  auto daemon = rig.start_daemon("daemon");
  ASSERT_TRUE(wait_until([&] { return rig.answers(); }, 30s)) << daemon->log();
  std::this_thread::sleep_for(1s);  // the CANopen nodes' first heartbeats

  // WHEN a calibration runs to its end
  ASSERT_TRUE(rig.ask("start")["ok"].boolean()) << daemon->log();
  const calibctl::JsonValue status = rig.wait_for_end(240s);

  // THEN it reaches its solve (whose validation refuses a fit the model
  // cannot explain, or finds too many rows off to be gross errors) and its
  // samples are kept in its history entry
  const std::string state = status["state"].string(), reason = status["reason"].string();
  std::printf("run: %s %s\n", state.c_str(), reason.substr(0, 160).c_str());
  ASSERT_TRUE(state == "done" || reason.rfind("fit refused: ", 0) == 0)
      << state << ": " << reason << "\n" << daemon->log();
  const std::string entry = status["run"]["entry"].string();
  ASSERT_FALSE(entry.empty());
  EXPECT_GE(data_rows(entry + "/samples.csv"), 18) << read_text(entry + "/samples.csv");
  EXPECT_TRUE(std::filesystem::exists(entry + "/robot.toml"));
  // AND the model check after the solve names the effect (calibctl status;
  // calibctl show too when the fit was committed)
  calibctl::JsonValue run;
  EXPECT_TRUE(wait_until(
      [&] {
        run = rig.ask("status")["run"];
        return !run["diagnosis"].string().empty();
      },
      120s));
  const std::string verdict = run["diagnosis"].string();
  std::printf("model check: %s\n", verdict.c_str());
  EXPECT_EQ(verdict.rfind(effect + ": ", 0), 0u) << verdict;
  EXPECT_EQ(verdict.find("structure remains"), std::string::npos) << verdict;
  if (state == "done") {
    EXPECT_EQ(rig.ask("show")["run"]["diagnosis"].string(), verdict);
  }
  EXPECT_NE(read_text(entry + "/run.toml").find(verdict), std::string::npos) << read_text(entry + "/run.toml");
  // AND cdpr-calib diagnose on the history entry adds the same effect
  ChildProcess diagnose({built_program("tools/cdpr-calib/cdpr-calib"), "diagnose", entry, "--output",
                         rig.dir + "/diagnosis"},
                        rig.dir + "/diagnose.log");
  const std::optional<int> exit_status = diagnose.wait_exit(120s);
  const std::string output = diagnose.log();
  std::printf("diagnose: %s\n", output.substr(output.find("\nsummary: ") + 1).c_str());
  EXPECT_TRUE(exit_status.has_value()) << output;
  EXPECT_EQ(summary_value(output, "added"), effect) << output;
  EXPECT_EQ(summary_value(output, "structure"), "none") << output;
}

TEST(HiddenEffectRun, ALoadCellBiasIsNamedByTheModelCheckAndByDiagnose) {
  expect_effect_named({"--force-bias", "15"}, "load_cell_bias");
}

TEST(HiddenEffectRun, ElasticCablesAreNamedByTheModelCheckAndByDiagnose) {
  expect_effect_named({"--axial-stiffness", "1.5e6"}, "elasticity");
}

}  // namespace
}  // namespace cdpr::integration
