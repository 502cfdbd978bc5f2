#include "solve_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "model_option.h"
#include "input_files.h"
#include "report.h"
#include "src/formats/calibration_toml.h"
#include "src/report/calibration_report.h"

namespace cdpr::tools {
namespace {

// DIR/report.html of a finished calibration; false after printing why not.
bool write_report(const SolveArgs& args, const CalibrationInputs& inputs, const CalibrationOptions& options,
                  const CalibrationResult& result, const std::optional<Truth>& truth) {
  const std::filesystem::path dir(args.report_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  std::ofstream out(dir / "report.html", std::ios::trunc);
  out << report::fitted_calibration_report_html(
      inputs.robot, inputs.samples, options, result, truth,
      {{"data", args.robot_path + (args.samples_path.empty() ? "" : ", " + args.samples_path)}});
  out.close();
  if (ec || !out) {
    std::fprintf(stderr, "cdpr-calib: cannot write %s\n", (dir / "report.html").c_str());
    return false;
  }
  std::fprintf(stdout, "wrote %s\n", (dir / "report.html").c_str());
  return true;
}

// A fit refused for its gross errors: the verdict first (the model or the
// sensors), then why; the full list of readings only without -q.
int refused(const SolveArgs& args, const CalibrationResult& result, const Robot& robot) {
  const bool model = result.refusal == Refusal::kModelMisfit;
  if (model) {
    std::fprintf(stderr, "cdpr-calib: the model does not fit (try `cdpr-calib diagnose %s%s%s`), not a sensor "
                 "fault; nothing written\n", args.robot_path.c_str(), args.samples_path.empty() ? "" : " ",
                 args.samples_path.c_str());
  } else {
    std::fprintf(stderr, "cdpr-calib: sensor fault: more rows with gross errors than allowed, and no model term "
                 "explains them; the robot or its sensors need attention; nothing written\n");
  }
  std::fprintf(stderr, "cdpr-calib: calibration refused: %s%s\n", result.message.c_str(),
               args.quiet ? " (all of them: run without -q)" : "");
  if (!args.quiet) print_summary(stdout, result, robot);
  if (args.verbose) print_stages(stdout, result.stages);
  return model ? kExitRefusedModelMisfit : 2;
}

}  // namespace

void add_solve_command(CLI::App& app, SolveArgs& args) {
  CLI::App* solve = app.add_subcommand("solve", "Calibrate anchors and encoder offsets from measured static poses");
  add_input_options(*solve, args.robot_path, args.samples_path);
  solve->add_option("-o,--output", args.output_path, "where to write calibration.toml")->capture_default_str();
  solve->add_option("--model", args.model,
                    "cable model: catenary (heavy sagging cable) or rigid (straight, massless), optionally followed "
                    "by model terms, comma-separated: " + effect_names_text() +
                        " (e.g. catenary,elasticity,load_cell); fitted terms go to [effects]")
      ->check(model_validator())->capture_default_str();
  solve->add_option("--huber", args.huber_width,
                    "Huber loss width in sigma units on the final fit (0 = least squares); gross errors are found "
                    "and left out without it (robust fit, then the rows of rejected readings refitted)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  solve->add_option("--height-sigma", args.height_sigma_m,
                    "sigma [m] of the catenary end-height consistency, Eq. (15)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  solve->add_option("--max-iterations", args.max_iterations, "Levenberg-Marquardt iteration limit")
      ->check(CLI::PositiveNumber)->capture_default_str();
  solve->add_option("--truth", args.truth_path, "truth.toml of a simulated data set: print the errors against it")
      ->check(CLI::ExistingFile);
  solve->add_option("--report", args.report_dir,
                    "also write DIR/report.html (created): verdict, anchors with their sigma ellipses, residual plots");
  solve->add_option("--max-rejected-fraction", args.max_rejected_fraction,
                    "refuse the calibration when more than this fraction of the rows have gross errors")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  solve->add_flag("--no-robust", args.least_squares,
                  "least squares (or --huber) alone: no robust fit, no gross errors found or left out");
  solve->add_flag("--accept-misfit", args.accept_misfit,
                  "exit 0 even when the model does not fit the data or the problem is under-determined (the "
                  "calibration.toml says so in model_warning either way)");
  solve->add_flag("-q,--quiet", args.quiet, "no per-iteration progress lines");
  solve->add_flag("-v,--verbose", args.verbose,
                  "also list the stages the calibration ran (robust fit, gross-error test, refits, restarts and "
                  "other starts taken as fallbacks), each with its iterations, cost and outcome");
}

int run_solve(const SolveArgs& args) {
  const std::optional<CalibrationInputs> inputs = read_inputs(args.robot_path, args.samples_path);
  if (!inputs) return 1;
  const Robot* const robot = &inputs->robot;
  const std::vector<Sample>* const samples = &inputs->samples;
  if (!args.quiet) {
    std::fprintf(stdout, "robot %s: %d cables, %zu samples, model %s\n", robot->name.c_str(), robot->cable_count(),
                 samples->size(), args.model.c_str());
  }

  CalibrationOptions options;
  const ModelChoice model = *parse_model(args.model);
  options.cable_model = model.cable_model;
  options.effects = model.effects;
  options.huber_width = args.huber_width;
  options.height_sigma_m = args.height_sigma_m;
  options.max_iterations = args.max_iterations;
  options.max_rejected_fraction = args.max_rejected_fraction;
  options.robust = !args.least_squares;
  if (!args.quiet) options.progress = [](const IterationSummary& it) { print_iteration(stdout, it); };

  CalibrationResult result = calibrate(*robot, *samples, options);
  if (!result.ok && result.refusal != Refusal::kNone) return refused(args, result, *robot);
  print_summary(stdout, result, *robot);
  if (args.verbose) print_stages(stdout, result.stages);
  if (!result.ok) {
    std::fprintf(stderr, "cdpr-calib: calibration failed: %s\n", result.message.c_str());
    return 2;
  }
  result.calibration.robot = robot->name;
  result.calibration.created = utc_timestamp_now();

  std::ofstream out(args.output_path, std::ios::trunc);
  out << formats::format_calibration_toml(result.calibration);
  out.close();
  if (!out) {
    std::fprintf(stderr, "cdpr-calib: cannot write %s\n", args.output_path.c_str());
    return 1;
  }
  std::fprintf(stdout, "wrote %s\n", args.output_path.c_str());

  std::optional<Truth> truth;
  if (!args.truth_path.empty()) {
    const auto read = formats::read_truth_toml(args.truth_path);
    if (!read) {
      std::fprintf(stderr, "cdpr-calib: %s\n", read.error().message().c_str());
      return 1;
    }
    truth = *read;
    print_truth_comparison(stdout, result.calibration, *truth);
  }
  if (!args.report_dir.empty() && !write_report(args, *inputs, options, result, truth)) return 1;
  if (result.misfit && !args.accept_misfit) {
    const std::string advice =
        result.misfit_cause == MisfitCause::kModel
            ? "run `cdpr-calib diagnose " + args.robot_path + " " + args.samples_path + "` to find the missing model term"
            : misfit_advice(result.misfit_cause);
    // -q keeps the warning's verdict (up to its first "; "): the terms and
    // noise scales behind it are in the summary and the report.
    const std::string& warning = result.calibration.model_warning;
    const std::string verdict = args.quiet ? warning.substr(0, warning.find("; ")) : warning;
    std::fprintf(stderr,
                 "cdpr-calib: %s%s\ncdpr-calib: the calibration was written but is not to be trusted as it is: %s; "
                 "or pass --accept-misfit\n",
                 verdict.c_str(), args.quiet && verdict.size() < warning.size() ? " (the rest: run without -q)" : "",
                 advice.c_str());
    return 3;
  }
  return 0;
}

}  // namespace cdpr::tools
