#pragma once
// Base for factors with compile-time sizes (Ceres' SizedCostFunction in
// spirit): kResiduals whitened residuals of variables with tangent sizes
// kBlockDims..., one per key in order. The derived class writes whitened
// residuals and, for each non-null block, the Jacobian; this base applies the
// robust loss (factor_support.h) and computes the cost, so no derived class
// can forget either. Fixed-size Eigen maps over the raw buffers: evaluating
// allocates nothing.
//
//   class RangeFactor final : public SizedFactor<1, 3> {
//    public:
//     RangeFactor(int i, double range_m, double sigma_m)
//         : SizedFactor({AnchorKey(i)}, Loss{}), ... {}
//    private:
//     bool evaluate_whitened(const double* const* x, double* r, double* const* j) const override {
//       Residuals residual(r);
//       ...
//       if (auto J = jacobian<0>(j)) J->noalias() = ...;  // 1x3 map, only when requested
//       return true;
//     }
//   };

#include <array>
#include <optional>

#include <Eigen/Core>

#include "solver/nls/factor.h"
#include "solver/nls/factor_support.h"
#include "solver/nls/loss.h"

namespace cdpr {

template <int kResiduals, int... kBlockDims>
class SizedFactor : public Factor {
 public:
  static constexpr int kBlocks = sizeof...(kBlockDims);
  static constexpr std::array<int, kBlocks> kDims = {kBlockDims...};
  static_assert(kResiduals > 0 && kBlocks > 0 && ((kBlockDims > 0) && ...));

  int residual_dim() const final { return kResiduals; }
  std::span<const Key> keys() const final { return keys_; }

  bool evaluate(const double* const* parameters, double* residual, double* const* jacobians,
                double* cost) const final {
    if (!evaluate_whitened(parameters, residual, jacobians)) return false;
    *cost = apply_loss(loss_, kResiduals, residual, jacobians, kDims);
    return true;
  }

 protected:
  using Residuals = Eigen::Map<Eigen::Matrix<double, kResiduals, 1>>;
  template <int kBlock>
  using Jacobian = Eigen::Map<Eigen::Matrix<double, kResiduals, kDims[kBlock],
                                            kDims[kBlock] == 1 ? Eigen::ColMajor : Eigen::RowMajor>>;

  SizedFactor(const std::array<Key, kBlocks>& keys, Loss loss) : keys_(keys), loss_(loss) {}

  // Map of block kBlock's row-major Jacobian, or nothing when it is not wanted.
  template <int kBlock>
  static std::optional<Jacobian<kBlock>> jacobian(double* const* jacobians) {
    static_assert(kBlock >= 0 && kBlock < kBlocks);
    if (jacobians == nullptr || jacobians[kBlock] == nullptr) return std::nullopt;
    return Jacobian<kBlock>(jacobians[kBlock]);
  }

  // Whitened residuals (before the loss) and the Jacobian blocks that are
  // non-null; false when the model cannot be evaluated here. Must not allocate.
  virtual bool evaluate_whitened(const double* const* parameters, double* residual,
                                 double* const* jacobians) const = 0;

 private:
  std::array<Key, kBlocks> keys_;
  Loss loss_;
};

}  // namespace cdpr
