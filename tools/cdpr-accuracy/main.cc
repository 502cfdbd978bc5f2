// cdpr-accuracy: calibration accuracy over many simulated data sets, and the
// paper's Table I model check against the simulator's equilibrium.
#include <cstdio>

#include <CLI/CLI.hpp>

#include "cdpr-accuracy/accuracy.h"
#include "cdpr-accuracy/model_check.h"
#include "version/version.h"

namespace {

void print_row(const char* what, const cdpr::accuracy::Distribution& d) {
  std::printf("  %-22s mean %8.4f  median %8.4f  p90 %8.4f  worst %8.4f\n", what, d.mean, d.median, d.p90, d.worst);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdpr-accuracy: calibration accuracy over many seeds of simulated data"};
  app.set_version_flag("--version", cdpr::version::version_text("cdpr-accuracy"));
  std::string preset_name = "large", model = "catenary";
  int poses = 35, seeds = 50, first_seed = 1;
  double perturbation = -1.0;
  std::vector<double> workspace;
  int design_candidates = 0;
  double noise_scale = 1.0;
  int max_iterations = cdpr::CalibrationOptions{}.max_iterations;
  bool model_check_only = false, verbose = false;
  app.add_option("--preset", preset_name, "large | small")->check(CLI::IsMember({"large", "small"}))->capture_default_str();
  app.add_option("--poses", poses, "static poses per data set")->capture_default_str();
  app.add_option("--seeds", seeds, "number of data sets (seeds first-seed ..)")->capture_default_str();
  app.add_option("--first-seed", first_seed, "first seed")->capture_default_str();
  app.add_option("--anchor-perturbation", perturbation,
                 "norm of the nominal anchors' error [m] (default: 10 large, 1 small)");
  app.add_option("--model", model, "catenary | rigid | both")->check(CLI::IsMember({"catenary", "rigid", "both"}))
      ->capture_default_str();
  app.add_option("--workspace", workspace, "waypoint box xmin,ymin,zmin,xmax,ymax,zmax [m] (default: the preset's)")
      ->delimiter(',')->expected(6);
  app.add_option("--design", design_candidates,
                 "0: poses spread evenly over the box; N: the most informative of N feasible candidates "
                 "(A-optimal on the nominal anchors, solver/pose_design.h)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--noise-scale", noise_scale,
                 "multiplies the preset's sensor noise; 0 = noiseless data fitted with the preset's sigmas, so the "
                 "reported sigmas are the model's Cramer-Rao bound for these poses")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--max-iterations", max_iterations, "Levenberg-Marquardt iterations per fit, at most")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--model-check", model_check_only, "only run the Table I model check");
  app.add_flag("-v,--verbose", verbose, "one line per run");
  CLI11_PARSE(app, argc, argv);

  const cdpr::sim::Preset preset = *cdpr::sim::parse_preset(preset_name);
  if (model_check_only) {
    const cdpr::accuracy::ModelCheck c = cdpr::accuracy::model_check(preset, poses, first_seed);
    if (!c.error.empty()) {
      std::fprintf(stderr, "cdpr-accuracy: %s\n", c.error.c_str());
      return 2;
    }
    std::printf("model check (%s, %d poses): MPE-L %.3e %% (max %.3e %%)  MPE-F %.3e %% (max %.3e %%)\n",
                preset_name.c_str(), c.poses, c.mean_length_error_pct, c.max_length_error_pct, c.mean_force_error_pct,
                c.max_force_error_pct);
    std::printf("  lengths [%.1f, %.1f] m  forces [%.1f, %.1f] N\n", c.min_length_m, c.max_length_m, c.min_force_n,
                c.max_force_n);
    return 0;
  }

  cdpr::accuracy::Case c;
  c.preset = preset;
  c.poses = poses;
  c.anchor_perturbation_m = perturbation >= 0 ? perturbation : (preset == cdpr::sim::Preset::kLarge ? 10.0 : 1.0);
  if (workspace.size() == 6) {
    c.workspace_min = Eigen::Vector3d(workspace[0], workspace[1], workspace[2]);
    c.workspace_max = Eigen::Vector3d(workspace[3], workspace[4], workspace[5]);
  }
  c.design_candidates = design_candidates;
  c.noise_scale = noise_scale;
  c.max_iterations = max_iterations;
  std::vector<cdpr::CableModelKind> models;
  if (model != "rigid") models.push_back(cdpr::CableModelKind::kCatenary);
  if (model != "catenary") models.push_back(cdpr::CableModelKind::kRigid);
  for (cdpr::CableModelKind kind : models) {
    c.model = kind;
    std::vector<cdpr::accuracy::RunResult> runs;
    for (int s = 0; s < seeds; ++s) {
      runs.push_back(cdpr::accuracy::run_case(c, static_cast<std::uint64_t>(first_seed + s)));
      const auto& r = runs.back();
      if (verbose) {
        std::printf("seed %3llu %s anchor %.4f m offset %.4f m iterations %d %s\n",
                    static_cast<unsigned long long>(r.seed), r.ok ? "ok    " : "FAILED", r.anchor_error_m,
                    r.offset_error_m, r.iterations, r.ok ? "" : r.message.c_str());
      } else {
        std::fprintf(stderr, "\r%s model: run %d/%d", kind == cdpr::CableModelKind::kRigid ? "rigid" : "catenary",
                     s + 1, seeds);
      }
    }
    std::fprintf(stderr, "\n");
    const cdpr::accuracy::Summary s = cdpr::accuracy::summarise(runs);
    std::printf("%s / %d poses / %s model / perturbation %.1f m: %d runs, %d failed (scored as uncalibrated), "
                "mean iterations %.1f\n",
                preset_name.c_str(), poses, kind == cdpr::CableModelKind::kRigid ? "rigid" : "catenary",
                c.anchor_perturbation_m, s.runs, s.failures, s.mean_iterations);
    print_row("pulley error [m]", s.anchor);
    print_row("|offset error| [m]", s.offset);
    std::printf("  normalised error RMS (error/sigma): %.2f\n", s.normalised_rms);
    std::printf("  anchor sigma norm, mean [m]: reported by the fit %.4f, straight-cable Cramer-Rao bound %.4f\n",
                s.mean_reported_sigma_m, s.mean_straight_bound_m);
  }
  return 0;
}
