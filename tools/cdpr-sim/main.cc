// cdpr-sim: simulated calibration data sets (robot.toml, samples.csv,
// truth.toml) from the true static equilibrium of a robot with heavy cables.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "rest_mode.h"
#include "sim/dataset.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"
#include "version/version.h"

namespace {

using cdpr::sim::DatasetConfig;

// "v" or "v0,v1,..." -> exactly `count` numbers (one value is repeated).
bool parse_list(const std::string& text, std::size_t count, std::vector<double>& out) {
  out.clear();
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    try {
      std::size_t used = 0;
      const std::string field = text.substr(start, comma - start);
      out.push_back(std::stod(field, &used));
      if (used != field.size()) return false;
    } catch (const std::exception&) {
      return false;
    }
    start = comma + 1;
  }
  if (out.size() == 1 && count > 1) out.assign(count, out[0]);
  return out.size() == count;
}

// "0:0.05,3:-0.05" -> drift[0] = 0.05, drift[3] = -0.05.
bool parse_drift(const std::string& text, std::array<double, cdpr::kCableCount>& drift) {
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string field = text.substr(start, comma - start);
    const std::size_t colon = field.find(':');
    if (colon == std::string::npos) return false;
    try {
      std::size_t used_cable = 0, used_value = 0;
      const int cable = std::stoi(field.substr(0, colon), &used_cable);
      const double value = std::stod(field.substr(colon + 1), &used_value);
      if (used_cable != colon || used_value != field.size() - colon - 1) return false;
      if (cable < 0 || cable >= cdpr::kCableCount) return false;
      drift[static_cast<std::size_t>(cable)] = value;
    } catch (const std::exception&) {
      return false;
    }
    start = comma + 1;
  }
  return true;
}

bool write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << text;
  file.close();
  if (!file) {
    std::fprintf(stderr, "cdpr-sim: cannot write %s\n", path.c_str());
    return false;
  }
  return true;
}

struct Args {
  std::string preset = "large";
  std::string out_dir;
  std::string encoder_scale, encoder_drift, com_offset, wind, workspace;
  std::string encoder_outlier_range = "0.5,2", force_spike_range = "50,500";
  std::uint64_t seed = 1;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"cdpr-sim: simulated self-calibration data from the true static equilibrium of a cable robot "
               "with heavy (optionally elastic) cables; writes robot.toml (nominal), samples.csv (sensor "
               "readings) and truth.toml (true anchors, offsets and hidden effects)"};
  app.set_version_flag("--version", cdpr::version::version_text("cdpr-sim"));
  Args args;
  DatasetConfig config;
  app.add_option("--preset", args.preset, "robot of the paper's Table I: large (240x220x50 m) or small (12.5x4.5x28.5 m)")
      ->check(CLI::IsMember({"large", "small"}))->capture_default_str();
  app.add_option("--poses", config.pose_count, "number of static poses (samples)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--seed", args.seed, "random seed: waypoints, offsets, anchor perturbation, noise")->capture_default_str();
  app.add_option("--out", args.out_dir, "output directory (created): robot.toml, samples.csv, truth.toml")->required();
  app.add_option("--anchor-perturbation", config.anchor_perturbation_m,
                 "robot.toml's nominal anchors = true anchors + a random vector of this norm [m]")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--axial-stiffness", config.effects.axial_stiffness_n,
                 "hidden elasticity: cable EA [N] (default inextensible); encoders then count unstretched cable")
      ->check(CLI::PositiveNumber);
  app.add_option("--encoder-scale", args.encoder_scale,
                 "hidden encoder scale s: one value for all cables or 4 comma-separated; "
                 "reading = (1 + s) * payout + offset");
  app.add_option("--encoder-drift", args.encoder_drift,
                 "unknown effect: encoders drifting over the run, CABLE:METRES[,CABLE:METRES...]; the reading of "
                 "sample k of n gains METRES * k / (n - 1) (e.g. 0:0.05,3:-0.05)");
  app.add_option("--force-bias", config.effects.force_bias_n, "hidden load-cell bias b [N]: reading = (1 + g) * tension + b");
  app.add_option("--force-gain", config.effects.force_gain, "hidden load-cell gain error g");
  app.add_option("--com-offset", args.com_offset, "hidden centre-of-mass offset x,y,z [m, platform frame]");
  app.add_option("--density-error", config.effects.density_error, "hidden cable density error r: true = nominal * (1 + r)")
      ->check(CLI::Range(-0.9, 10.0));
  app.add_flag_callback("--weightless-cables", [&config] { config.effects.density_error = -1.0; },
                        "rigid weightless truth: straight massless cables (density error -1), which a catenary "
                        "model cannot fit; for the misfit verdict of cdpr-calib solve");
  app.add_option("--orientation-noise-factor", config.orientation_noise_factor,
                 "true orientation noise = this times the sigma robot.toml states (no physical effect; for the "
                 "noise terms of cdpr-calib diagnose)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--pulley-radius", config.effects.pulley_radius_m, "hidden swivel-pulley radius [m] (docs/DESIGN.md)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--wind", args.wind, "unknown effect: constant force fx,fy,fz [N, world] on the platform at its CoM");
  app.add_option("--workspace", args.workspace,
                 "waypoint box xmin,ymin,zmin,xmax,ymax,zmax [m] of the platform origin (default: the preset's, "
                 "which spans the paper's Table I ranges; a wider box makes the anchors better observable)");
  app.add_option("--design", config.design_candidates,
                 "0: poses spread evenly over the box; N: the --poses most informative of N feasible candidates "
                 "(D-optimal on the nominal anchors, solver/calibration/pose_design.h)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--noise-scale", config.noise_scale,
                 "multiplies every sensor sigma (encoder 10 mm, force 5 N large / 1 N small, pose 5 mm, 0.01 rad); 0 = noiseless")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--encoder-outliers", config.gross_errors.encoder_fraction,
                 "fraction of rows with one gross encoder error (one cable, chosen at random; at least one row when "
                 "> 0); listed in truth.toml [[outlier]]")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--encoder-outlier-range", args.encoder_outlier_range,
                 "min,max size [m] of a gross encoder error (sign at random)")->capture_default_str();
  app.add_option("--force-spikes", config.gross_errors.force_fraction,
                 "fraction of rows with a load-cell spike (at least one row when > 0); listed in truth.toml [[outlier]]")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--force-spike-range", args.force_spike_range, "min,max size [N] of a load-cell spike (sign at random)")
      ->capture_default_str();
  app.add_option("--segments", config.segments, "Simpson segments per cable in the equilibrium")
      ->check(CLI::PositiveNumber)->capture_default_str();
  cdpr::tools::RestModeArgs rest_args;
  cdpr::tools::add_rest_mode_options(app, rest_args);
  CLI11_PARSE(app, argc, argv);

  config.preset = *cdpr::sim::parse_preset(args.preset);
  config.seed = args.seed;
  std::vector<double> values;
  if (!args.encoder_scale.empty()) {
    if (!parse_list(args.encoder_scale, cdpr::kCableCount, values)) {
      std::fprintf(stderr, "cdpr-sim: --encoder-scale: expected 1 or %d comma-separated numbers\n", cdpr::kCableCount);
      return 1;
    }
    std::copy(values.begin(), values.end(), config.effects.encoder_scale.begin());
  }
  if (!args.encoder_drift.empty() && !parse_drift(args.encoder_drift, config.effects.encoder_drift_m)) {
    std::fprintf(stderr, "cdpr-sim: --encoder-drift: expected CABLE:METRES[,CABLE:METRES...] with CABLE 0 to %d\n",
                 cdpr::kCableCount - 1);
    return 1;
  }
  for (auto [text, target, name] : {std::tuple{&args.com_offset, &config.effects.com_offset_platform, "--com-offset"},
                                    std::tuple{&args.wind, &config.effects.wind_force_world_n, "--wind"}}) {
    if (text->empty()) continue;
    if (!parse_list(*text, 3, values)) {
      std::fprintf(stderr, "cdpr-sim: %s: expected 3 comma-separated numbers\n", name);
      return 1;
    }
    *target = Eigen::Vector3d(values[0], values[1], values[2]);
  }

  for (auto [text, low, high, name] :
       {std::tuple{&args.encoder_outlier_range, &config.gross_errors.encoder_min_m, &config.gross_errors.encoder_max_m,
                   "--encoder-outlier-range"},
        std::tuple{&args.force_spike_range, &config.gross_errors.force_min_n, &config.gross_errors.force_max_n,
                   "--force-spike-range"}}) {
    if (!parse_list(*text, 2, values) || !(values[0] >= 0.0 && values[0] <= values[1])) {
      std::fprintf(stderr, "cdpr-sim: %s: expected min,max with 0 <= min <= max\n", name);
      return 1;
    }
    *low = values[0];
    *high = values[1];
  }

  if (!args.workspace.empty()) {
    if (!parse_list(args.workspace, 6, values) || values.size() != 6) {
      std::fprintf(stderr, "cdpr-sim: --workspace: expected 6 comma-separated numbers xmin,ymin,zmin,xmax,ymax,zmax\n");
      return 1;
    }
    config.workspace_min = Eigen::Vector3d(values[0], values[1], values[2]);
    config.workspace_max = Eigen::Vector3d(values[3], values[4], values[5]);
  }

  if (rest_args.rests > 0) {
    std::error_code made;
    std::filesystem::create_directories(args.out_dir, made);
    if (made) {
      std::fprintf(stderr, "cdpr-sim: cannot create %s: %s\n", args.out_dir.c_str(), made.message().c_str());
      return 1;
    }
    return cdpr::tools::run_rest_mode(config, rest_args, args.out_dir);
  }
  const auto data = cdpr::sim::simulate_dataset(config);
  if (!data) {
    std::fprintf(stderr, "cdpr-sim: %s\n", data.error().c_str());
    return 2;
  }
  const std::filesystem::path dir(args.out_dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    std::fprintf(stderr, "cdpr-sim: cannot create %s: %s\n", dir.c_str(), ec.message().c_str());
    return 1;
  }
  if (!write_file(dir / "robot.toml", cdpr::formats::format_robot_toml(data->nominal))) return 1;
  std::printf("wrote %s: robot %s, nominal anchors %.3g m from the truth\n", (dir / "robot.toml").c_str(),
              data->nominal.name.c_str(), config.anchor_perturbation_m);
  if (!write_file(dir / "samples.csv", cdpr::formats::format_samples_csv(data->samples))) return 1;
  std::printf("wrote %s: %zu samples (%d candidate poses skipped), noise scale %g\n", (dir / "samples.csv").c_str(),
              data->samples.size(), data->skipped_candidates, config.noise_scale);
  if (!write_file(dir / "truth.toml", cdpr::formats::format_truth_toml(data->truth))) return 1;
  std::printf("wrote %s: %zu hidden effects, %zu planted gross errors\n", (dir / "truth.toml").c_str(),
              data->truth.effects.size(), data->truth.outliers.size());

  double length_min = 1e300, length_max = 0.0, force_min = 1e300, force_max = 0.0;
  for (const cdpr::sim::Equilibrium& state : data->states) {
    for (const cdpr::sim::CableEquilibrium& cable : state.cables) {
      length_min = std::min(length_min, cable.arc_length_m);
      length_max = std::max(length_max, cable.arc_length_m);
    }
    const double force = state.cables[data->nominal.reference_cable].tension_n;
    force_min = std::min(force_min, force);
    force_max = std::max(force_max, force);
  }
  std::printf("cable length [%.1f, %.1f] m, reference force [%.1f, %.1f] N\n", length_min, length_max, force_min,
              force_max);
  return 0;
}
