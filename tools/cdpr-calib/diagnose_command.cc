#include "diagnose_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "diagnosis_report.h"
#include "model_option.h"
#include "input_files.h"
#include "report.h"
#include "sim/discriminating_poses.h"
#include "solver/calibration/noise_components.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/waypoints_csv.h"

namespace cdpr::tools {
namespace {

bool write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::trunc);
  file << text;
  file.close();
  if (!file) std::fprintf(stderr, "cdpr-calib: cannot write %s\n", path.c_str());
  return static_cast<bool>(file);
}

// The sigmas diagnose weighed the readings with at its end: robot.toml's,
// scaled by its noise findings as its steps scaled them (scale_noise).
NoiseSigmas final_noise(const Robot& robot, const Diagnosis& d) {
  Robot scaled = robot;
  std::vector<Sample> no_rows;
  CalibrationOptions unused;
  for (const NoiseFinding& f : d.noise) scale_noise(f.group, f.scale, scaled, no_rows, unused);
  return scaled.noise;
}

// For each standing mimic set, the waypoints that tell its members apart
// (sim/discriminating_poses.h): their text for the report, and the
// waypoints to write.
std::string discrimination_text(const Robot& robot, const std::vector<Sample>& samples, const Diagnosis& d,
                                const DiagnoseArgs& args, std::vector<formats::PlannedWaypoint>* waypoints) {
  std::string text;
  sim::DiscriminationOptions options;
  options.count = args.discriminate;
  if (args.workspace.size() == 6) {
    options.workspace_min = Eigen::Vector3d(args.workspace[0], args.workspace[1], args.workspace[2]);
    options.workspace_max = Eigen::Vector3d(args.workspace[3], args.workspace[4], args.workspace[5]);
  }
  for (const MimicSet* set : standing_mimic_sets(d)) {
    std::string names;
    for (const MimicMember& m : set->members) {
      names += (names.empty() ? "" : " or ") + mimic_member_name(m);
    }
    const sim::DiscriminatingPoses poses = sim::discriminating_poses(robot, final_noise(robot, d), samples, *set, options);
    if (poses.waypoints.empty()) {
      text += "DISCRIMINATE: " + names + ": no waypoints (" + poses.message + ")\n";
      continue;
    }
    char line[400];
    std::snprintf(line, sizeof line,
                  "DISCRIMINATE: %s: at the %zu poses measured their predictions differ by at most %.1f sigma; "
                  "%zu waypoints where they differ by %.1f-%.1f sigma (of %d feasible candidates):\n",
                  names.c_str(), samples.size(), poses.measured_separation_sigma, poses.waypoints.size(),
                  poses.waypoints.back().separation_sigma, poses.waypoints.front().separation_sigma, poses.feasible);
    text += line;
    for (const formats::PlannedWaypoint& w : poses.waypoints) {
      std::snprintf(line, sizeof line, "  x %.2f  y %.2f  z %.2f  separation %.1f sigma\n", w.position_world.x(),
                    w.position_world.y(), w.position_world.z(), w.separation_sigma);
      text += line;
      waypoints->push_back(w);
    }
  }
  return text;
}

}  // namespace

void add_diagnose_command(CLI::App& app, DiagnoseArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "diagnose",
      "Find where the model and the data disagree: by cross-validation, rank the known model terms by how much they "
      "improve the prediction of held-out poses, add the best while it is significant, and say when structure "
      "remains that no known term explains");
  add_input_options(*cmd, args.robot_path, args.samples_path);
  cmd->add_option("-o,--output", args.report_dir,
                  "report directory (created): report.txt, report.html, calibration.toml of the final model")
      ->capture_default_str();
  cmd->add_option("--truth", args.truth_path, "truth.toml of a simulated data set: anchor errors and true effect values")
      ->check(CLI::ExistingFile);
  cmd->add_option("--candidates", args.candidates, "comma-separated model terms to try (default all: " +
                                                       effect_names_text() + ")");
  cmd->add_option("--folds", args.folds,
                  "cross-validation folds: each pose is predicted by a fit without its fold (sample k in fold k % n)")
      ->check(CLI::Range(2, 20))->capture_default_str();
  cmd->add_option("--alpha", args.alpha, "family-wise significance level per round (Bonferroni over the candidates)")
      ->check(CLI::Range(1e-12, 0.5))->capture_default_str();
  cmd->add_option("--max-added", args.max_added, "add at most this many terms")
      ->check(CLI::Range(0, 7))->capture_default_str();
  cmd->add_option("--height-sigma", args.height_sigma_m, "sigma [m] of the catenary end-height consistency, Eq. (15)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--discriminate", args.discriminate,
                  "when terms mimic each other on these poses: this many extra waypoints where their predictions "
                  "differ most, printed and written to waypoints.csv in the report directory (0: none)")
      ->check(CLI::Range(0, 100))->capture_default_str();
  cmd->add_option("--workspace", args.workspace,
                  "box xmin,ymin,zmin,xmax,ymax,zmax [m] of the platform origin to choose those waypoints in "
                  "(default: the box of the poses measured)")
      ->delimiter(',')->expected(6);
}

int run_diagnose(const DiagnoseArgs& args) {
  const std::optional<CalibrationInputs> inputs = read_inputs(args.robot_path, args.samples_path);
  if (!inputs) return 1;
  const Robot* const robot = &inputs->robot;
  const std::vector<Sample>* const samples = &inputs->samples;
  ReportContext context{robot->name, robot->noise, std::nullopt, robot};
  if (!args.truth_path.empty()) {
    auto truth = formats::read_truth_toml(args.truth_path);
    if (!truth) {
      std::fprintf(stderr, "cdpr-calib: %s\n", truth.error().message().c_str());
      return 1;
    }
    context.truth = *truth;
  }

  DiagnosisOptions options;
  options.fit.height_sigma_m = args.height_sigma_m;
  options.folds = args.folds;
  options.alpha = args.alpha;
  options.max_added = args.max_added;
  if (!args.candidates.empty()) {
    std::string why;
    const auto choice = parse_model(args.candidates, &why);
    if (!choice || choice->effects.empty()) {
      std::fprintf(stderr, "cdpr-calib: --candidates: %s\n", choice ? "no model term named" : why.c_str());
      return 1;
    }
    options.candidates = choice->effects;
  }
  options.progress = [](const std::string& line) { std::fprintf(stderr, "diagnose: %s\n", line.c_str()); };

  const Diagnosis diagnosis = diagnose(*robot, *samples, options);
  std::string text = diagnosis_text(diagnosis, context);
  std::vector<formats::PlannedWaypoint> waypoints;
  if (diagnosis.ok && args.discriminate > 0 && !standing_mimic_sets(diagnosis).empty()) {
    std::fprintf(stderr, "diagnose: choosing waypoints that tell the mimic set apart\n");
    text += discrimination_text(*robot, *samples, diagnosis, args, &waypoints);
  }
  std::fputs(text.c_str(), stdout);
  if (!diagnosis.ok) return 2;

  const std::filesystem::path dir(args.report_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "cdpr-calib: cannot create %s: %s\n", dir.c_str(), ec.message().c_str());
    return 1;
  }
  if (!write_text(dir / "report.txt", text) || !write_text(dir / "report.html", diagnosis_html(diagnosis, context))) {
    return 1;
  }
  std::printf("wrote %s and %s\n", (dir / "report.txt").c_str(), (dir / "report.html").c_str());
  if (!waypoints.empty()) {
    const std::string comment = "waypoints that tell the mimicking terms apart (cdpr-calib diagnose " +
                                args.samples_path + ")";
    if (!write_text(dir / "waypoints.csv", formats::format_waypoints_csv(waypoints, comment))) return 1;
    std::printf("wrote %s: measure these and diagnose again (cdpr-sim --extra-positions on simulated data)\n",
                (dir / "waypoints.csv").c_str());
  }
  if (diagnosis.final_fit.ok) {
    Calibration calibration = diagnosis.final_fit.calibration;
    calibration.robot = robot->name;
    calibration.created = utc_timestamp_now();
    if (!write_text(dir / "calibration.toml", formats::format_calibration_toml(calibration))) return 1;
    std::printf("wrote %s\n", (dir / "calibration.toml").c_str());
  }
  return 0;
}

}  // namespace cdpr::tools
