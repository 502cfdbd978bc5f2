#include "diagnose_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "diagnosis_report.h"
#include "model_option.h"
#include "input_files.h"
#include "report.h"
#include "src/formats/calibration_toml.h"

namespace cdpr::tools {
namespace {

bool write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::trunc);
  file << text;
  file.close();
  if (!file) std::fprintf(stderr, "cdpr-calib: cannot write %s\n", path.c_str());
  return static_cast<bool>(file);
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
  const std::string text = diagnosis_text(diagnosis, context);
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
