#include "localize_command.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "solver/operation/localize.h"
#include "solver/operation/rest_problem.h"
#include "src/formats/samples_csv.h"

namespace cdpr::tools {
namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;
using Matrix6 = Eigen::Matrix<double, 6, 6>;

// The covariance of the measured pose: its position and orientation sigmas
// (isotropic, so the same in the world frame).
Matrix6 measured_covariance(const Robot& robot, const Sample& rest) {
  const SampleSigmas s = reading_sigmas(robot, rest);
  Vector6 variance;
  variance << Eigen::Vector3d::Constant(s.position_m * s.position_m),
      Eigen::Vector3d::Constant(s.orientation_rad * s.orientation_rad);
  return variance.asDiagonal();
}

// RMS accumulators of the comparison with the true poses.
struct TruthErrors {
  double position_sq = 0.0, orientation_sq = 0.0, normalised_sq = 0.0;
  double position_max = 0.0, orientation_max = 0.0;
  int rows = 0;
  void add(const Vector6& error, const Matrix6& covariance) {
    position_sq += error.head<3>().squaredNorm();
    orientation_sq += error.tail<3>().squaredNorm();
    position_max = std::max(position_max, error.head<3>().norm());
    orientation_max = std::max(orientation_max, error.tail<3>().norm());
    normalised_sq += error.cwiseQuotient(covariance.diagonal().cwiseSqrt()).squaredNorm();
    ++rows;
  }
};

}  // namespace

void add_localize_command(CLI::App& app, LocalizeArgs& args) {
  CLI::App* cmd = app.add_subcommand(
      "localize",
      "The platform pose from the cables at every row (forward kinematics with sag, the calibration as priors): "
      "pose, sigma, and the measured pose's difference from it in sigmas");
  add_operation_inputs(*cmd, args.inputs);
  cmd->add_option("-o,--output", args.output_path, "CSV file to write (default: standard output)");
  cmd->add_option("--true-poses", args.true_poses_path,
                  "samples.csv whose poses are the truth (cdpr-sim --rests: true_poses.csv): print the errors")
      ->check(CLI::ExistingFile);
  cmd->add_option("--calibration-samples", args.calibration_samples_path,
                  "the samples.csv the calibration was fitted on: the priors get the joint covariance of its "
                  "anchors and offsets instead of their per-axis sigmas (honest sigmas; docs/operation.md)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--exact-calibration", args.exact_calibration,
                "hold the calibration exact instead of as priors of its sigmas");
  cmd->add_option("--height-sigma", args.height_sigma_m, "sigma [m] of the catenary end-height consistency, Eq. (15)")
      ->check(CLI::PositiveNumber)->capture_default_str();
}

int run_localize(const LocalizeArgs& args) {
  const std::optional<OperationInputs> in = read_operation_inputs(args.inputs);
  if (!in) return 1;
  std::vector<Sample> truth;
  if (!args.true_poses_path.empty()) {
    auto read = formats::read_samples_csv(args.true_poses_path, in->robot.cable_count());
    if (!read) {
      std::fprintf(stderr, "cdpr-calib: %s\n", read.error().message().c_str());
      return 1;
    }
    truth = std::move(*read);
    if (truth.size() != in->rests.size()) {
      std::fprintf(stderr, "cdpr-calib: %s has %zu rows, %s %zu\n", args.true_poses_path.c_str(), truth.size(),
                   args.inputs.samples.c_str(), in->rests.size());
      return 1;
    }
  }
  LocalizeOptions options;
  options.calibration_priors = !args.exact_calibration;
  options.height_sigma_m = args.height_sigma_m;
  if (!args.calibration_samples_path.empty() &&
      !read_calibration_covariance(args.calibration_samples_path, *in, args.height_sigma_m, options.calibration_covariance)) {
    return 1;
  }

  std::ostringstream out;
  out << "# cdpr-calib localize (docs/operation.md): pose from the cables [m, rotation vector rad, world], its "
         "1-sigma, measured - from the cables in sigmas of both, chi-square (6 dof) of that difference\n";
  out << "id,x,y,z,rx,ry,rz,sigma_x,sigma_y,sigma_z,sigma_rx,sigma_ry,sigma_rz,"
         "dx_sigma,dy_sigma,dz_sigma,drx_sigma,dry_sigma,drz_sigma,pose_chi2,status\n";
  out.precision(9);
  int failed = 0;
  double measured_sq = 0.0;
  int measured_rows = 0;
  TruthErrors errors;
  std::optional<Pose> previous;
  for (std::size_t k = 0; k < in->rests.size(); ++k) {
    const Sample& rest = in->rests[k];
    const Pose start = previous ? *previous : nominal_start(in->calibration, rest);
    std::string why;
    const std::optional<LocalizedPose> pose = localize_rest(in->robot, in->calibration, rest, start, options, &why);
    out << rest.id;
    if (!pose) {
      ++failed;
      for (int c = 0; c < 19; ++c) out << ',';
      out << ",\"no pose: " << why << "\"\n";
      continue;
    }
    previous = pose->world_T_platform;
    const Eigen::Vector3d p = pose->world_T_platform.position_world;
    const Eigen::Vector3d r = so3_log(pose->world_T_platform.world_R_platform);
    const Vector6 sigma = pose->covariance.diagonal().cwiseSqrt();
    out << ',' << p.x() << ',' << p.y() << ',' << p.z() << ',' << r.x() << ',' << r.y() << ',' << r.z();
    for (int j = 0; j < 6; ++j) out << ',' << sigma(j);
    if (has_measured_pose(rest)) {
      const Matrix6 both = pose->covariance + measured_covariance(in->robot, rest);
      const Vector6 d = pose_difference(Pose{rest.position_world, rest.world_R_platform}, pose->world_T_platform);
      const Vector6 z = d.cwiseQuotient(both.diagonal().cwiseSqrt());
      for (int j = 0; j < 6; ++j) out << ',' << z(j);
      out << ',' << mahalanobis_squared(d, both);
      measured_sq += z.squaredNorm();
      measured_rows += 1;
    } else {
      for (int j = 0; j < 7; ++j) out << ',';
    }
    out << (pose->converged ? ",ok\n" : ",iteration limit\n");
    if (!truth.empty()) {
      errors.add(pose_difference(Pose{truth[k].position_world, truth[k].world_R_platform}, pose->world_T_platform),
                 pose->covariance);
    }
  }

  if (args.output_path.empty()) {
    std::fputs(out.str().c_str(), stdout);
  } else {
    std::ofstream file(args.output_path, std::ios::trunc);
    file << out.str();
    file.close();
    if (!file) {
      std::fprintf(stderr, "cdpr-calib: cannot write %s\n", args.output_path.c_str());
      return 1;
    }
  }
  std::fprintf(stderr, "localized %zu of %zu rows", in->rests.size() - failed, in->rests.size());
  if (measured_rows > 0) {
    std::fprintf(stderr, "; measured pose - pose from the cables: RMS %.3f sigma (1 expected)",
                 std::sqrt(measured_sq / (6.0 * measured_rows)));
  }
  std::fprintf(stderr, "\n");
  if (errors.rows > 0) {
    std::fprintf(stderr,
                 "against the true poses: rows=%d position_rms_m=%.5f position_max_m=%.5f orientation_rms_rad=%.6f "
                 "orientation_max_rad=%.6f error_over_sigma_rms=%.3f\n",
                 errors.rows, std::sqrt(errors.position_sq / errors.rows), errors.position_max,
                 std::sqrt(errors.orientation_sq / errors.rows), errors.orientation_max,
                 std::sqrt(errors.normalised_sq / (6.0 * errors.rows)));
  }
  return failed == 0 ? 0 : 2;
}

}  // namespace cdpr::tools
