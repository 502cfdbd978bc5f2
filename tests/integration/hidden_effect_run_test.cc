// The daemon against a virtual robot that hides an effect robot.toml does
// not describe, as tools/demo.sh runs it (large preset, time scale 20,
// nominal anchors 0.3 m off, the shipped equilibrium thresholds): the run's
// samples stay in its history entry, the model check after the solve names
// the effect in `calibctl status` (and `show` when the fit was committed),
// and `cdpr-calib diagnose` on the entry names the same one; committing with
// that term is the operator's explicit `calibctl commit --with-term`.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "solver/calibration/calibrate.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"
#include "../read_text.h"
#include "slowdown.h"
#include "virtual_robot_process.h"

namespace cdpr::integration {
namespace {

using namespace std::chrono_literals;

using cdpr::test::read_text;

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

// status "run" once its model check is done (or as it is after 120 s).
calibctl::JsonValue model_check_of_last_run(const VirtualRobotProcess& rig) {
  calibctl::JsonValue run;
  rig.wait_until_robot(
      [&] {
        run = rig.ask("status")["run"];
        return !run["diagnosis"].string().empty();
      },
      slowed(120s));
  return run;
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
  ASSERT_TRUE(wait_until([&] { return rig.answers(); }, slowed(30s))) << daemon->log();
  std::this_thread::sleep_for(1s);  // the CANopen nodes' first heartbeats

  // WHEN a calibration runs to its end
  ASSERT_TRUE(rig.ask("start")["ok"].boolean()) << daemon->log();
  const calibctl::JsonValue status = rig.wait_for_end(slowed(240s));

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
  const calibctl::JsonValue run = model_check_of_last_run(rig);
  EXPECT_FALSE(run["diagnosis"].string().empty());
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
  const std::optional<int> exit_status = diagnose.wait_exit(slowed(120s));
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

// Mean distance of the fitted anchors from the true ones [m].
double mean_anchor_error(const Calibration& fit, const Truth& truth) {
  double sum = 0.0;
  for (std::size_t i = 0; i < fit.winches.size(); ++i) {
    sum += (fit.winches[i].anchor_world - truth.winches[i].anchor_world).norm();
  }
  return sum / static_cast<double>(fit.winches.size());
}

TEST(HiddenEffectRun, TheOperatorCommitsTheNamedLoadCellBiasWithCalibctl) {
  // GIVEN the virtual large robot whose load cell reads 15 N too much, as the demo runs it
  VirtualRobotProcess rig("large", 20, "", {"--anchor-perturbation", "0.3", "--force-bias", "15"});
  auto daemon = rig.start_daemon("daemon");
  ASSERT_TRUE(wait_until([&] { return rig.answers(); }, slowed(30s))) << daemon->log();
  std::this_thread::sleep_for(1s);  // the CANopen nodes' first heartbeats
  // AND a run whose fit the catenary cannot explain: refused, nothing committed
  ASSERT_TRUE(rig.ask("start")["ok"].boolean()) << daemon->log();
  const calibctl::JsonValue status = rig.wait_for_end(slowed(240s));
  ASSERT_EQ(status["reason"].string().rfind("fit refused: ", 0), 0u) << status["reason"].string();
  ASSERT_FALSE(rig.ask("show")["present"].boolean());
  const std::string entry = status["run"]["entry"].string();
  // AND its model check names load_cell_bias, and calibctl status says how to commit with it
  const calibctl::JsonValue run = model_check_of_last_run(rig);
  ASSERT_FALSE(run["diagnosis"].string().empty());
  std::printf("model check: %s\n", run["diagnosis"].string().c_str());
  ASSERT_EQ(run["named_terms"].array().size(), 1u) << run["diagnosis"].string();
  EXPECT_EQ(run["named_terms"].array()[0].string(), "load_cell_bias");
  const std::string calibctl = built_program("tools/calibctl/calibctl");
  ChildProcess hint({calibctl, "--socket", rig.socket, "status"}, rig.dir + "/status.log");
  EXPECT_EQ(hint.wait_exit(slowed(30s)), std::optional<int>(0));
  EXPECT_NE(hint.log().find("calibctl commit --with-term load_cell_bias run-000001"), std::string::npos)
      << hint.log();
  // AND requests the daemon cannot serve are refused with their reason
  EXPECT_NE(rig.ask("refit bias")["error"].string().find("unknown model term 'bias'"), std::string::npos);
  EXPECT_NE(rig.ask("refit load_cell_bias 9")["error"].string().find("no such run: run-000009"), std::string::npos);

  // WHEN the operator commits with the named term
  ChildProcess commit({calibctl, "--socket", rig.socket, "commit", "--with-term", "load_cell_bias", "run-000001"},
                      rig.dir + "/commit.log");
  const std::optional<int> exit_status = commit.wait_exit(slowed(240s));
  std::printf("calibctl commit --with-term: %s\n", commit.log().c_str());

  // THEN a calibration with the catenary plus the bias is committed
  ASSERT_EQ(exit_status, std::optional<int>(0)) << commit.log() << daemon->log();
  const calibctl::JsonValue show = rig.ask("show");
  ASSERT_TRUE(show["present"].boolean());
  const auto model = show["model"].array();
  ASSERT_EQ(model.size(), 2u);
  EXPECT_EQ(model[0].string(), "catenary");
  EXPECT_EQ(model[1].string(), "load_cell_bias");
  // AND its bias is the planted one within 3 sigma
  const auto committed = formats::read_calibration_toml(rig.state_dir + "/calibration.toml");
  ASSERT_TRUE(committed) << committed.error().message();
  const double bias = committed->effects.at("force_bias").at(0);
  const double sigma = committed->effects.at("force_bias_sigma").at(0);
  std::printf("force_bias = %.3f +- %.3f N (planted 15)\n", bias, sigma);
  EXPECT_LE(std::abs(bias - 15.0), 3.0 * sigma);
  // AND its anchors are closer to the truth than the refused catenary fit's (the daemon's solver options)
  const auto truth = formats::read_truth_toml(rig.dir + "/robot/truth.toml");
  const auto robot = formats::read_robot_toml(entry + "/robot.toml");
  ASSERT_TRUE(truth && robot);
  const auto samples = formats::read_samples_csv(entry + "/samples.csv", robot->cable_count());
  ASSERT_TRUE(samples);
  const CalibrationResult refused = calibrate(*robot, *samples, CalibrationOptions{});
  const double refit_error = mean_anchor_error(*committed, *truth);
  const double refused_error = mean_anchor_error(refused.calibration, *truth);
  std::printf("mean anchor error: refit %.2f mm, refused catenary fit %.2f mm\n", 1e3 * refit_error,
              1e3 * refused_error);
  EXPECT_LT(refit_error, refused_error);
  // AND it is kept in the history like a run's commit, with its report, and logged
  calibctl::JsonValue kept = show["run"];
  ASSERT_FALSE(kept.is_null());
  EXPECT_EQ(kept["entry"].string(), rig.state_dir + "/history/run-000002");
  EXPECT_TRUE(wait_until(
      [&] {
        kept = rig.ask("show")["run"];
        return !kept["report"].is_null();
      },
      slowed(120s)));
  EXPECT_NE(read_text(kept["entry"].string() + "/run.toml").find("refit_of = 1"), std::string::npos);
  EXPECT_NE(daemon->log().find("refit of run-000001 committed: committed calibration 1"), std::string::npos)
      << daemon->log();
}

}  // namespace
}  // namespace cdpr::integration
