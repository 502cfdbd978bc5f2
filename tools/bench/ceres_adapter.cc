#include "ceres_adapter.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cdpr::bench {
namespace {

// Right perturbation of solver/nls/pose.h: p + d_p, q * Exp(d_theta).
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    for (int i = 0; i < 3; ++i) x_plus_delta[i] = x[i] + delta[i];
    const Eigen::Vector3d theta(delta[3], delta[4], delta[5]);
    const double angle = theta.norm();
    const Eigen::Quaterniond dq = angle > 0.0 ? Eigen::Quaterniond(Eigen::AngleAxisd(angle, theta / angle))
                                              : Eigen::Quaterniond::Identity();
    const Eigen::Quaterniond q = (Eigen::Quaterniond(x[3], x[4], x[5], x[6]) * dq).normalized();
    x_plus_delta[3] = q.w(); x_plus_delta[4] = q.x(); x_plus_delta[5] = q.y(); x_plus_delta[6] = q.z();
    return true;
  }
  bool PlusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
    J = rotation_plus_jacobian_block(x);
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    for (int i = 0; i < 3; ++i) y_minus_x[i] = y[i] - x[i];
    const Eigen::Quaterniond dq = Eigen::Quaterniond(x[3], x[4], x[5], x[6]).conjugate() *
                                  Eigen::Quaterniond(y[3], y[4], y[5], y[6]);
    const Eigen::AngleAxisd aa(dq.normalized());
    const Eigen::Vector3d theta = aa.angle() * aa.axis();
    for (int i = 0; i < 3; ++i) y_minus_x[3 + i] = theta(i);
    return true;
  }
  bool MinusJacobian(const double* x, double* jacobian) const override {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
    J = tangent_from_ambient(x);
    return true;
  }

  // d(q * (1, v/2)) / dv = 0.5 [-q_vec^T; q_w I + [q_vec]x].
  static Eigen::Matrix<double, 7, 6> rotation_plus_jacobian_block(const double* x) {
    Eigen::Matrix<double, 7, 6> J = Eigen::Matrix<double, 7, 6>::Zero();
    J.topLeftCorner<3, 3>().setIdentity();
    const double w = x[3];
    const Eigen::Vector3d v(x[4], x[5], x[6]);
    J.block<1, 3>(3, 3) = -0.5 * v.transpose();
    Eigen::Matrix3d skew_v;
    skew_v << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    J.block<3, 3>(4, 3) = 0.5 * (w * Eigen::Matrix3d::Identity() + skew_v);
    return J;
  }
  // A left inverse L of the plus Jacobian P (L P = I, since P_rot^T P_rot = I/4
  // for a unit quaternion): tangent Jacobians become ambient ones as J_t * L.
  static Eigen::Matrix<double, 6, 7> tangent_from_ambient(const double* x) {
    Eigen::Matrix<double, 6, 7> L = Eigen::Matrix<double, 6, 7>::Zero();
    L.topLeftCorner<3, 3>().setIdentity();
    L.bottomRightCorner<3, 4>() = 4.0 * rotation_plus_jacobian_block(x).bottomRightCorner<4, 3>().transpose();
    return L;
  }
};

class FactorCost final : public ceres::CostFunction {
 public:
  // Scratch for the tangent Jacobians of the pose blocks lives on the stack
  // (Evaluate runs inside Ceres' loop; allocating there would handicap Ceres).
  static constexpr int kMaxResiduals = 16;
  static constexpr int kMaxPoseBlocks = 2;
  static constexpr std::size_t kMaxKeys = 16;

  FactorCost(const Factor& factor, std::vector<bool> is_pose, const std::vector<int>& ambient_dims)
      : factor_(factor), is_pose_(std::move(is_pose)) {
    set_num_residuals(factor.residual_dim());
    *mutable_parameter_block_sizes() = ambient_dims;
    const auto poses = std::count(is_pose_.begin(), is_pose_.end(), true);
    if (factor.residual_dim() > kMaxResiduals || poses > kMaxPoseBlocks) {
      std::fprintf(stderr, "ceres_adapter: factor too large for the stack scratch\n");
      std::abort();
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    double cost = 0.0;
    if (jacobians == nullptr) return factor_.evaluate(parameters, residuals, nullptr, &cost);
    const int m = num_residuals();
    // Our factors return tangent Jacobians; poses need them in ambient form.
    std::array<double, kMaxPoseBlocks * kMaxResiduals * 6> tangent;
    std::array<double*, kMaxKeys> pointers{};
    int pose_slot = 0;
    for (std::size_t b = 0; b < is_pose_.size(); ++b) {
      if (jacobians[b] == nullptr) continue;
      pointers[b] = is_pose_[b] ? tangent.data() + (pose_slot++) * kMaxResiduals * 6 : jacobians[b];
    }
    if (!factor_.evaluate(parameters, residuals, pointers.data(), &cost)) return false;
    for (std::size_t b = 0; b < is_pose_.size(); ++b) {
      if (jacobians[b] == nullptr || !is_pose_[b]) continue;
      const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor>> Jt(pointers[b], m, 6);
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>> Ja(jacobians[b], m, 7);
      Ja.noalias() = Jt * PoseManifold::tangent_from_ambient(parameters[b]);
    }
    return true;
  }

 private:
  const Factor& factor_;
  std::vector<bool> is_pose_;
};

}  // namespace

void add_to_ceres(Problem& problem, ceres::Problem& ceres_problem) {
  double* state = problem.state().data();
  for (const Problem::Variable& v : problem.variables()) {
    double* block = state + v.ambient_offset;
    if (v.is_pose) {
      ceres_problem.AddParameterBlock(block, 7, new PoseManifold);
    } else {
      ceres_problem.AddParameterBlock(block, v.ambient_dim);
    }
    if (v.constant) ceres_problem.SetParameterBlockConstant(block);
  }
  for (const auto& factor : problem.factors()) {
    if (factor->keys().size() > FactorCost::kMaxKeys) {
      std::fprintf(stderr, "ceres_adapter: factor has too many keys\n");
      std::abort();
    }
    std::vector<bool> is_pose;
    std::vector<int> ambient_dims;
    std::vector<double*> blocks;
    for (const Key& key : factor->keys()) {
      const Problem::Variable& v = problem.variables()[problem.variable_index(key)];
      is_pose.push_back(v.is_pose);
      ambient_dims.push_back(v.ambient_dim);
      blocks.push_back(state + v.ambient_offset);
    }
    ceres_problem.AddResidualBlock(new FactorCost(*factor, std::move(is_pose), ambient_dims), nullptr, blocks);
  }
}

double our_cost(const Problem& problem) {
  double total = 0.0;
  std::vector<double> residual;
  std::vector<const double*> parameters;
  for (const auto& factor : problem.factors()) {
    residual.resize(factor->residual_dim());
    parameters.clear();
    for (const Key& key : factor->keys()) {
      parameters.push_back(problem.state().data() + problem.variables()[problem.variable_index(key)].ambient_offset);
    }
    double cost = 0.0;
    if (!factor->evaluate(parameters.data(), residual.data(), nullptr, &cost)) return std::numeric_limits<double>::infinity();
    total += cost;
  }
  return total;
}

}  // namespace cdpr::bench
