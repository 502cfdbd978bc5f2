#include "solver/nls/problem.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>

#include "solver/nls/factor_support.h"

namespace cdpr {
namespace {

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "cdpr::Problem: %s\n", what.c_str());
  std::abort();
}

constexpr int kPoseAmbient = 7;  // x, y, z, qw, qx, qy, qz
constexpr int kPoseTangent = 6;  // d_p, d_theta

}  // namespace

void Problem::add_variable(Key key, int tangent_dim, int ambient_dim, bool is_pose, const double* value) {
  if (has(key)) die("variable " + to_string(key) + " added twice");
  if (tangent_dim <= 0) die("variable " + to_string(key) + " has no dimensions");
  Variable v;
  v.key = key;
  v.tangent_dim = tangent_dim;
  v.ambient_dim = ambient_dim;
  v.ambient_offset = static_cast<int>(state_.size());
  v.is_pose = is_pose;
  const int index = static_cast<int>(variables_.size());
  const std::size_t kind = static_cast<std::size_t>(key.kind);
  if (key.index >= 0 && key.index < kDenseIndexLimit) {
    if (dense_index_.size() <= kind) dense_index_.resize(kind + 1);
    std::vector<int>& table = dense_index_[kind];
    if (table.size() <= static_cast<std::size_t>(key.index)) {
      table.resize(std::max<std::size_t>(static_cast<std::size_t>(key.index) + 1, 2 * table.size()), -1);
    }
    table[key.index] = index;
  } else {
    sparse_index_.emplace(key, index);
  }
  variables_.push_back(v);
  state_.insert(state_.end(), value, value + ambient_dim);
}

void Problem::add_pose(Key key, const Pose& value) {
  const Eigen::Quaterniond q = value.world_R_platform.normalized();
  const double ambient[kPoseAmbient] = {value.position_world.x(), value.position_world.y(), value.position_world.z(),
                                        q.w(), q.x(), q.y(), q.z()};
  add_variable(key, kPoseTangent, kPoseAmbient, true, ambient);
}

void Problem::add_vector(Key key, const Eigen::VectorXd& value) {
  const int n = static_cast<int>(value.size());
  add_variable(key, n, n, false, value.data());
}

void Problem::set_constant(Key key, bool constant) {
  if (!has(key)) die("set_constant of unknown variable " + to_string(key));
  variables_[find(key)].constant = constant;
}

int Problem::find(Key key) const {
  if (key.index >= 0 && key.index < kDenseIndexLimit) {
    const std::size_t kind = static_cast<std::size_t>(key.kind);
    if (kind >= dense_index_.size() || static_cast<std::size_t>(key.index) >= dense_index_[kind].size()) return -1;
    return dense_index_[kind][key.index];
  }
  const auto it = sparse_index_.find(key);
  return it == sparse_index_.end() ? -1 : it->second;
}

int Problem::variable_index(Key key) const {
  const int v = find(key);
  if (v < 0) die("unknown variable " + to_string(key));
  return v;
}

void Problem::add_factor(std::unique_ptr<Factor> factor) {
  if (!factor) die("null factor");
  if (factor->residual_dim() <= 0) die("factor " + std::to_string(factors_.size()) + " has no residuals");
  const std::span<const Key> keys = factor->keys();
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!has(keys[i])) {
      die("factor " + std::to_string(factors_.size()) + " names unknown variable " + to_string(keys[i]));
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (keys[j] == keys[i]) {
        die("factor " + std::to_string(factors_.size()) + " names " + to_string(keys[i]) + " twice");
      }
    }
  }
  factors_.push_back(std::move(factor));
}

const Problem::Variable& Problem::checked(Key key, bool is_pose) const {
  const Variable& v = variables_[variable_index(key)];
  if (v.is_pose != is_pose) die(to_string(key) + (is_pose ? " is not a pose" : " is a pose, not a vector"));
  return v;
}

Pose Problem::pose(Key key) const {
  return pose_from_parameters(state_.data() + checked(key, true).ambient_offset);
}

Eigen::VectorXd Problem::vector(Key key) const {
  const Variable& v = checked(key, false);
  return Eigen::Map<const Eigen::VectorXd>(state_.data() + v.ambient_offset, v.ambient_dim);
}

void Problem::set_pose(Key key, const Pose& value) {
  double* a = state_.data() + checked(key, true).ambient_offset;
  const Eigen::Quaterniond q = value.world_R_platform.normalized();
  a[0] = value.position_world.x();
  a[1] = value.position_world.y();
  a[2] = value.position_world.z();
  a[3] = q.w();
  a[4] = q.x();
  a[5] = q.y();
  a[6] = q.z();
}

void Problem::set_vector(Key key, const Eigen::VectorXd& value) {
  const Variable& v = checked(key, false);
  if (value.size() != v.ambient_dim) {
    die("set_vector of " + to_string(key) + " with " + std::to_string(value.size()) + " values, expected " +
        std::to_string(v.ambient_dim));
  }
  Eigen::Map<Eigen::VectorXd>(state_.data() + v.ambient_offset, v.ambient_dim) = value;
}

void Problem::retract(int v, const double* step) { retract(v, step, state_.data()); }

void Problem::retract(int v, const double* step, double* state) const {
  const Variable& var = variables_[v];
  retract_ambient(var.is_pose, var.ambient_dim, step, state + var.ambient_offset);
}

EliminationOrder Problem::elimination_order() const {
  const int nv = static_cast<int>(variables_.size());
  EliminationOrder order;
  order.group.assign(nv, EliminationOrder::kKept);
  for (int v = 0; v < nv; ++v) {
    const Variable& var = variables_[v];
    if (var.constant) continue;
    const bool pose = var.key.kind == VariableKind::kPose;
    if (!pose && var.key.kind != VariableKind::kReferenceForce) {
      order.kept.push_back(v);
      continue;
    }
    // The pose's other variable opened its group if it came first.
    const int other = find(pose ? ReferenceForceKey(var.key.index) : PoseKey(var.key.index));
    const bool other_grouped = other >= 0 && order.group[other] != EliminationOrder::kKept;
    order.group[v] = other_grouped ? order.group[other] : order.group_count++;
  }
  std::stable_sort(order.kept.begin(), order.kept.end(),
                   [&](int a, int b) { return variables_[a].key < variables_[b].key; });
  return order;
}

void retract_ambient(bool is_pose, int ambient_dim, const double* step, double* ambient) {
  if (!is_pose) {
    for (int i = 0; i < ambient_dim; ++i) ambient[i] += step[i];
    return;
  }
  Pose p = pose_from_parameters(ambient);
  retract(p, step);
  ambient[0] = p.position_world.x();
  ambient[1] = p.position_world.y();
  ambient[2] = p.position_world.z();
  ambient[3] = p.world_R_platform.w();
  ambient[4] = p.world_R_platform.x();
  ambient[5] = p.world_R_platform.y();
  ambient[6] = p.world_R_platform.z();
}

}  // namespace cdpr
