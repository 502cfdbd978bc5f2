#include "solver/calibration/noise_components.h"

#include <array>
#include <cmath>

#include <Eigen/Cholesky>

#include "solver/calibration/chi_square.h"
#include "solver/calibration/effect_pose_factor.h"
#include "solver/calibration/fitted_row_factors.h"
#include "solver/calibration/pose_factor_rows.h"

namespace cdpr {
namespace {

constexpr int kLocalDim = 8;  // pose tangent (6) and reference force (2)
constexpr int kPriorRows = 6;
constexpr int kFactorRows = EffectPoseFactor::kResidualDim;
constexpr int kRowCount = kPriorRows + kFactorRows;

// The group of residual row `row` of a pose's stacked rows: the pose prior's
// six (position, then orientation), then the reading factor's.
NoiseGroup group_of(int row) {
  if (row < 3) return NoiseGroup::kPosition;
  if (row < kPriorRows) return NoiseGroup::kOrientation;
  const int reading = row - kPriorRows;
  if (reading < kCableCount) return NoiseGroup::kEncoder;
  return reading == kForceRow ? NoiseGroup::kLoadCell : NoiseGroup::kHeight;
}

// One pose's stacked whitened rows at the fit: [local | global] columns.
struct PoseRows {
  Eigen::Matrix<double, kRowCount, Eigen::Dynamic> jacobian;
  Eigen::Matrix<double, kRowCount, 1> residual;
  std::array<bool, kRowCount> kept{};
};

bool linearise(const Robot& robot, const CalibrationOptions& options, const CalibrationResult& result, int k,
               int global_dim, PoseRows& out) {
  const FittedRow& row = result.fitted_rows[k];
  std::array<double, 7> pose{};
  std::array<double, 2> force{};
  std::array<std::array<double, 3>, kCableCount> anchors{};
  std::array<double, kCableCount> offsets{};
  for (int i = 0; i < kCableCount; ++i) {
    const WinchCalibration& w = result.calibration.winches[i];
    for (int a = 0; a < 3; ++a) anchors[i][a] = w.anchor_world(a);
    offsets[i] = w.offset_m;
  }
  std::vector<const double*> parameters{pose.data(), force.data()};
  std::vector<int> dims{6, 2};
  std::vector<int> column{0, 6};
  for (int i = 0; i < kCableCount; ++i) {
    parameters.push_back(anchors[i].data());
    dims.push_back(3);
    column.push_back(kLocalDim + 4 * i);
  }
  for (int i = 0; i < kCableCount; ++i) {
    parameters.push_back(&offsets[i]);
    dims.push_back(1);
    column.push_back(kLocalDim + 4 * i + 3);
  }
  int next = kLocalDim + 4 * kCableCount;
  for (std::size_t j = 0; j < options.effects.size(); ++j) {
    parameters.push_back(result.effects[j].value.data());
    dims.push_back(effect_dimension(options.effects[j]));
    column.push_back(next);
    next += dims.back();
  }
  std::vector<std::vector<double>> blocks;
  std::vector<double*> jacobians;
  for (int d : dims) blocks.emplace_back(static_cast<std::size_t>(kFactorRows) * d, 0.0);
  for (auto& b : blocks) jacobians.push_back(b.data());
  std::array<double, kPriorRows * 6> prior_jacobian{};
  double* prior_jacobians[] = {prior_jacobian.data()};
  std::array<double, kFactorRows> residual{};
  std::array<double, kPriorRows> prior_residual{};
  if (!evaluate_fitted_row(robot, row, k, options.height_sigma_m, Loss{options.huber_width}, options.effects,
                           pose.data(), force.data(), parameters.data(),
                           {prior_residual.data(), prior_jacobians, residual.data(), jacobians.data()})) {
    return false;
  }
  out.jacobian.setZero(kRowCount, kLocalDim + global_dim);
  for (int r = 0; r < kPriorRows; ++r) {
    out.residual(r) = prior_residual[r];
    for (int c = 0; c < 6; ++c) out.jacobian(r, c) = prior_jacobian[r * 6 + c];
  }
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    for (int r = 0; r < kFactorRows; ++r) {
      for (int c = 0; c < dims[b]; ++c) out.jacobian(kPriorRows + r, column[b] + c) = blocks[b][r * dims[b] + c];
    }
  }
  for (int r = 0; r < kFactorRows; ++r) out.residual(kPriorRows + r) = residual[r];
  const LeftOutRows left_out = left_out_rows(row.sample);
  for (int r = 0; r < kRowCount; ++r) out.kept[r] = r < kPriorRows || !left_out.contains(r - kPriorRows);
  return out.jacobian.allFinite() && out.residual.allFinite();
}

}  // namespace

std::string_view noise_group_name(NoiseGroup group) {
  switch (group) {
    case NoiseGroup::kEncoder: return "encoder";
    case NoiseGroup::kLoadCell: return "load_cell";
    case NoiseGroup::kPosition: return "position";
    case NoiseGroup::kOrientation: return "orientation";
    case NoiseGroup::kHeight: return "height";
  }
  return "?";
}

std::string_view noise_group_description(NoiseGroup group) {
  switch (group) {
    case NoiseGroup::kEncoder: return "encoder noise";
    case NoiseGroup::kLoadCell: return "load-cell noise";
    case NoiseGroup::kPosition: return "position noise";
    case NoiseGroup::kOrientation: return "orientation noise";
    case NoiseGroup::kHeight: return "height consistency";
  }
  return "?";
}

std::vector<NoiseComponent> noise_components(const Robot& robot, const CalibrationOptions& options,
                                             const CalibrationResult& result) {
  if (!result.ok || options.cable_model != CableModelKind::kCatenary || result.fitted_rows.empty() ||
      result.calibration.winches.size() != static_cast<std::size_t>(kCableCount) ||
      result.effects.size() != options.effects.size()) {
    return {};
  }
  int global_dim = 4 * kCableCount;
  for (Effect e : options.effects) global_dim += effect_dimension(e);
  const int n = static_cast<int>(result.fitted_rows.size());
  std::vector<PoseRows> rows(n);
  // The information over the globals with each pose's own unknowns
  // eliminated (Schur complement), and per pose its A^-1 and A^-1 B.
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(global_dim, global_dim);
  std::vector<Eigen::Matrix<double, kLocalDim, kLocalDim>> a_inverse(n);
  std::vector<Eigen::MatrixXd> a_inverse_b(n);
  for (int k = 0; k < n; ++k) {
    if (!linearise(robot, options, result, k, global_dim, rows[k])) return {};
    const auto& J = rows[k].jacobian;
    const Eigen::Matrix<double, kLocalDim, kLocalDim> a = J.leftCols<kLocalDim>().transpose() * J.leftCols<kLocalDim>();
    const Eigen::MatrixXd b = J.leftCols<kLocalDim>().transpose() * J.rightCols(global_dim);
    const Eigen::LLT<Eigen::Matrix<double, kLocalDim, kLocalDim>> llt(a);
    if (llt.info() != Eigen::Success) return {};
    a_inverse[k] = llt.solve(Eigen::Matrix<double, kLocalDim, kLocalDim>::Identity());
    a_inverse_b[k] = a_inverse[k] * b;
    reduced += J.rightCols(global_dim).transpose() * J.rightCols(global_dim) - b.transpose() * a_inverse_b[k];
  }
  const Eigen::LLT<Eigen::MatrixXd> reduced_llt(reduced);
  if (reduced_llt.info() != Eigen::Success) return {};
  const Eigen::MatrixXd global_covariance = reduced_llt.solve(Eigen::MatrixXd::Identity(global_dim, global_dim));

  std::array<NoiseComponent, kNoiseGroupCount> groups;
  for (int g = 0; g < kNoiseGroupCount; ++g) groups[g].group = static_cast<NoiseGroup>(g);
  for (int k = 0; k < n; ++k) {
    // The inverse of the whole information over this pose's unknowns and the globals.
    Eigen::MatrixXd covariance(kLocalDim + global_dim, kLocalDim + global_dim);
    const Eigen::MatrixXd cross = -a_inverse_b[k] * global_covariance;
    covariance.topLeftCorner<kLocalDim, kLocalDim>() = a_inverse[k] - cross * a_inverse_b[k].transpose();
    covariance.topRightCorner(kLocalDim, global_dim) = cross;
    covariance.bottomLeftCorner(global_dim, kLocalDim) = cross.transpose();
    covariance.bottomRightCorner(global_dim, global_dim) = global_covariance;
    const PoseRows& pose = rows[k];
    for (int r = 0; r < kRowCount; ++r) {
      if (!pose.kept[r]) continue;
      const Eigen::RowVectorXd j = pose.jacobian.row(r);
      const double leverage = j * covariance * j.transpose();
      NoiseComponent& c = groups[static_cast<int>(group_of(r))];
      ++c.rows;
      c.chi_square += pose.residual(r) * pose.residual(r);
      c.redundancy += std::max(0.0, 1.0 - leverage);
    }
  }
  std::vector<NoiseComponent> out;
  for (NoiseComponent& c : groups) {
    if (c.rows == 0 || !(c.redundancy > 0.0)) continue;
    const double ratio = c.chi_square / c.redundancy;
    c.scale = std::sqrt(ratio);
    c.p_high = scaled_chi_square_upper_tail(c.chi_square, c.redundancy, 2.0 * c.redundancy);
    c.likelihood_gain = ratio > 0.0 ? std::max(0.0, c.chi_square - c.redundancy - c.redundancy * std::log(ratio)) : 0.0;
    out.push_back(c);
  }
  return out;
}

void scale_noise(NoiseGroup group, double factor, Robot& robot, std::vector<Sample>& samples,
                 CalibrationOptions& options) {
  auto scale = [&](double& sigma) { sigma *= factor; };
  switch (group) {
    case NoiseGroup::kEncoder:
      scale(robot.noise.encoder_m);
      for (Sample& s : samples) {
        if (s.has_own_sigma()) for (double& e : s.sigma.encoder_m) scale(e);
      }
      return;
    case NoiseGroup::kLoadCell:
      scale(robot.noise.force_n);
      for (Sample& s : samples) {
        if (s.has_own_sigma()) scale(s.sigma.force_n);
      }
      return;
    case NoiseGroup::kPosition:
      scale(robot.noise.position_m);
      for (Sample& s : samples) {
        if (s.has_own_sigma()) scale(s.sigma.position_m);
      }
      return;
    case NoiseGroup::kOrientation:
      scale(robot.noise.orientation_rad);
      for (Sample& s : samples) {
        if (s.has_own_sigma()) scale(s.sigma.orientation_rad);
      }
      return;
    case NoiseGroup::kHeight: scale(options.height_sigma_m); return;
  }
}

}  // namespace cdpr
