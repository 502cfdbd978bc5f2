#include "solver/linalg/schur_complement.h"

#include <algorithm>
#include <cmath>
#include <type_traits>

#include <Eigen/Core>

#include "solver/linalg/block_copy.h"
#include "solver/linalg/dense_kernels.h"
#include "solver/linalg/group_kernels.h"

namespace cdpr {
namespace {

using namespace group_kernels;

// out(r, c) += sum_i Ja(i, r) Jb(i, c), Ja and Jb row-major m x da and
// m x db, out column-major with leading dimension `stride`. Sizes known at
// compile time for the tangent sizes that occur (pose 6, anchor 3,
// reference force 2, offset 1), so the small loops unroll.
template <int DA, int DB>
void add_block_fixed(int m, int, int, const double* ja, const double* jb, double* out, int stride) {
  Eigen::Matrix<double, DA, DB> sum = Eigen::Matrix<double, DA, DB>::Zero();
  for (int i = 0; i < m; ++i) {
    sum.noalias() += Eigen::Map<const Eigen::Matrix<double, DA, 1>>(ja + i * DA) *
                     Eigen::Map<const Eigen::Matrix<double, 1, DB>>(jb + i * DB);
  }
  for (int c = 0; c < DB; ++c) {
    for (int r = 0; r < DA; ++r) out[r + stride * c] += sum(r, c);
  }
}

void add_block_any(int m, int da, int db, const double* ja, const double* jb, double* out, int stride) {
  for (int c = 0; c < db; ++c) {
    for (int r = 0; r < da; ++r) {
      double sum = 0.0;
      for (int i = 0; i < m; ++i) sum += ja[i * da + r] * jb[i * db + c];
      out[r + stride * c] += sum;
    }
  }
}

template <int DA>
SchurComplement::BlockKernel kernel_for(int db) {
  switch (db) {
    case 1: return add_block_fixed<DA, 1>;
    case 2: return add_block_fixed<DA, 2>;
    case 3: return add_block_fixed<DA, 3>;
    case 6: return add_block_fixed<DA, 6>;
    default: return add_block_any;
  }
}

SchurComplement::BlockKernel kernel_for(int da, int db) {
  switch (da) {
    case 1: return kernel_for<1>(db);
    case 2: return kernel_for<2>(db);
    case 3: return kernel_for<3>(db);
    case 6: return kernel_for<6>(db);
    default: return add_block_any;
  }
}

}  // namespace

std::unique_ptr<SchurComplement> SchurComplement::create(BlockJacobian& jacobian, const EliminationOrder& order) {
  const int nv = jacobian.variable_count();
  // The groups of the non-constant variables.
  std::vector<int> group_of(nv, -1);
  std::vector<int> group_dim(order.group_count, 0);
  int global_dim = 0;
  for (int v = 0; v < nv; ++v) {
    if (jacobian.constant(v)) continue;
    const int g = order.group[v];
    if (g == EliminationOrder::kKept) {
      global_dim += jacobian.variable_dim(v);
      continue;
    }
    group_of[v] = g;
    group_dim[g] += jacobian.variable_dim(v);
    if (group_dim[g] > kMaxGroupDim) return nullptr;
  }
  if (group_dim.empty() || global_dim == 0 || global_dim > kMaxGlobalDim) return nullptr;
  for (int f = 0; f < jacobian.factor_count(); ++f) {
    if (jacobian.key_count(f) > 255) return nullptr;  // BlockOp holds key positions in a byte
    int group = -1;
    for (int k = 0; k < jacobian.key_count(f); ++k) {
      const int g = group_of[jacobian.key_variable(f, k)];
      if (g < 0) continue;
      if (group >= 0 && g != group) return nullptr;  // couples two groups: not block diagonal
      group = g;
    }
  }
  // Columns: each group's variables together (in variable order), then the
  // globals in the order given (a problem lists the variables of one kind
  // side by side: a factor's Jacobian columns of a kind share their zero
  // rows, and side by side they make one run of its J^T J).
  const int groups = order.group_count;
  std::vector<int> next_column(groups, 0);
  int local_dim = 0;
  for (int g = 0; g < groups; ++g) {
    next_column[g] = local_dim;
    local_dim += group_dim[g];
  }
  std::vector<int> variable_column(nv, -1);
  for (int v = 0; v < nv; ++v) {
    if (group_of[v] < 0) continue;
    variable_column[v] = next_column[group_of[v]];
    next_column[group_of[v]] += jacobian.variable_dim(v);
  }
  int global_column = local_dim;
  for (int v : order.kept) {
    variable_column[v] = global_column;
    global_column += jacobian.variable_dim(v);
  }
  jacobian.assign_columns(std::move(variable_column));
  return std::unique_ptr<SchurComplement>(new SchurComplement(jacobian, group_of, groups));
}

SchurComplement::SchurComplement(const BlockJacobian& jacobian, const std::vector<int>& group_of, int group_count)
    : jacobian_(jacobian) {
  const int nv = jacobian_.variable_count();
  const int nf = jacobian_.factor_count();
  auto column_of = [&](int v) { return jacobian_.variable_column(v); };

  // Group sizes and columns.
  groups_.assign(group_count, Group{});
  for (Group& g : groups_) g.column = -1;
  for (int v = 0; v < nv; ++v) {
    const int g = group_of[v];
    if (g < 0) {
      if (column_of(v) >= 0) global_dim_ += jacobian_.variable_dim(v);
      continue;
    }
    Group& group = groups_[g];
    group.column = group.column < 0 ? column_of(v) : std::min(group.column, column_of(v));
    group.dim += jacobian_.variable_dim(v);
    local_dim_ += jacobian_.variable_dim(v);
  }
  const int n = global_dim_;
  auto global_column = [&](int v) { return column_of(v) - local_dim_; };

  // Each factor's group, the global variables in column order, and which
  // of them each group's factors reach (a groups x globals table).
  std::vector<int> globals;
  for (int v = 0; v < nv; ++v) {
    if (group_of[v] < 0 && column_of(v) >= 0) globals.push_back(v);
  }
  std::sort(globals.begin(), globals.end(), [&](int x, int y) { return column_of(x) < column_of(y); });
  const std::size_t global_count = globals.size();
  std::vector<int> global_index(nv, -1);
  for (std::size_t i = 0; i < global_count; ++i) global_index[globals[i]] = static_cast<int>(i);
  std::vector<unsigned char> reaches(group_count * global_count, 0);
  std::vector<int>& factor_group = factor_group_;
  factor_group.assign(nf, -1);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < jacobian_.key_count(f); ++k) {
      const int g = group_of[jacobian_.key_variable(f, k)];
      if (g >= 0) factor_group[f] = g;
    }
    const int g = factor_group[f];
    if (g < 0) continue;
    for (int k = 0; k < jacobian_.key_count(f); ++k) {
      const int i = global_index[jacobian_.key_variable(f, k)];
      if (i >= 0) reaches[g * global_count + i] = 1;
    }
  }
  int block_total = 0, coupling_total = 0;
  for (int g = 0; g < group_count; ++g) {
    Group& group = groups_[g];
    group.coupled_begin = static_cast<int>(coupled_.size());
    for (std::size_t i = 0; i < global_count; ++i) {
      if (!reaches[g * global_count + i]) continue;
      const int v = globals[i];
      for (int d = 0; d < jacobian_.variable_dim(v); ++d) coupled_.push_back(global_column(v) + d);
    }
    group.coupled_end = static_cast<int>(coupled_.size());
    group.contiguous = true;
    for (int k = group.coupled_begin + 1; k < group.coupled_end; ++k) {
      group.contiguous = group.contiguous && coupled_[k] == coupled_[k - 1] + 1;
    }
    group.block = block_total;
    group.coupling = coupling_total;
    block_total += group.dim * group.dim;
    coupling_total += group.dim * (group.coupled_end - group.coupled_begin);
  }
  a_.assign(block_total, 0.0);
  factor_.assign(block_total, 0.0);
  b_.assign(coupling_total, 0.0);
  w_.assign(coupling_total, 0.0);
  c_.assign(static_cast<std::size_t>(n) * n, 0.0);
  s_.assign(static_cast<std::size_t>(n) * n, 0.0);
  reduced_rhs_.assign(n, 0.0);
  inverse_diagonal_.assign(local_dim_, 0.0);
  reduced_inverse_diagonal_.assign(n, 0.0);
  group_zeroed_.assign(group_count, 0);

  // Block operations of every factor: each pair of non-constant keys once,
  // oriented so the block lands in an upper triangle or in B.
  op_begin_.reserve(nf + 1);
  plans_.assign(nf, FactorPlan{});
  gather_column_.assign(jacobian_.key_offset(nf), -1);
  std::size_t widest = 0, gathered_size = 0;
  RunCache run_cache;
  for (int f = 0; f < nf; ++f) {
    op_begin_.push_back(static_cast<int>(ops_.size()));
    if (plan_gathered(f, factor_group[f], group_of, run_cache)) {
      const FactorPlan& plan = plans_[f];
      const std::size_t width = plan.local_count + plan.global_count;
      widest = std::max(widest, width);
      gathered_size = std::max(gathered_size, width * jacobian_.residual_dim(f));
      continue;
    }
    const int nk = jacobian_.key_count(f);
    for (int a = 0; a < nk; ++a) {
      for (int b = a; b < nk; ++b) {
        int ka = a, kb = b;
        int va = jacobian_.key_variable(f, ka), vb = jacobian_.key_variable(f, kb);
        if (column_of(va) < 0 || column_of(vb) < 0) continue;
        const bool local_a = group_of[va] >= 0, local_b = group_of[vb] >= 0;
        BlockOp op{};
        if (local_a && local_b) {
          if (column_of(va) > column_of(vb)) {
            std::swap(ka, kb);
            std::swap(va, vb);
          }
          const Group& group = groups_[group_of[va]];
          op = {static_cast<unsigned char>(ka), static_cast<unsigned char>(kb), kLocal,
                group.block + (column_of(va) - group.column) + group.dim * (column_of(vb) - group.column), group.dim,
                nullptr};
        } else if (local_a || local_b) {
          // B row-major: its transpose, column-major with leading dimension
          // m, takes the global key's rows and the local key's columns.
          if (local_a) {
            std::swap(ka, kb);
            std::swap(va, vb);
          }
          const Group& group = groups_[group_of[vb]];
          const int m = group.coupled_end - group.coupled_begin;
          const int position = static_cast<int>(
              std::find(coupled_.begin() + group.coupled_begin, coupled_.begin() + group.coupled_end, global_column(va)) -
              (coupled_.begin() + group.coupled_begin));
          op = {static_cast<unsigned char>(ka), static_cast<unsigned char>(kb), kCoupling,
                group.coupling + position + m * (column_of(vb) - group.column), m, nullptr};
        } else {
          if (column_of(va) > column_of(vb)) {
            std::swap(ka, kb);
            std::swap(va, vb);
          }
          op = {static_cast<unsigned char>(ka), static_cast<unsigned char>(kb), kGlobal,
                global_column(va) + n * global_column(vb), n, nullptr};
        }
        op.kernel = kernel_for(jacobian_.key_dim(f, op.a), jacobian_.key_dim(f, op.b));
        ops_.push_back(op);
      }
    }
  }
  op_begin_.push_back(static_cast<int>(ops_.size()));
  gathered_.assign(gathered_size, 0.0);
  gathered_gradient_.assign(widest, 0.0);
}

SchurComplement::~SchurComplement() = default;

void SchurComplement::accumulate_gathered(int slot, int f, double* gradient) {
  const BlockJacobian& lin = jacobian_;
  const FactorPlan& plan = plans_[f];
  const int m = lin.residual_dim(f), lc = plan.local_count, gc = plan.global_count, width = lc + gc;
  double* j = gathered_.data();
  if (plan.gaps) std::fill(j, j + m * width, 0.0);
  for (int k = 0; k < lin.key_count(f); ++k) {
    const int first = gather_column_[lin.key_offset(f) + k];
    if (first < 0) continue;
    copy_block_columns(m, lin.key_dim(f, k), lin.jacobian(slot, f, k), j + first, width);
  }
  // J^T r, then J^T J as its blocks A (local x local), B (local x global,
  // stored as its transpose, column-major) and C (global x global), each
  // run over the rows it reaches.
  const double* residual = lin.residuals(slot, f);
  double* g = gathered_gradient_.data();
  std::fill(g, g + width, 0.0);
  for (int r = plan.run_begin; r < plan.run_end; ++r) {
    const ColumnRun& run = runs_[r];
    if (depth(run.rows) == 0) continue;
    add_transposed_times_vector(depth(run.rows), run.width, j + run.rows.first * width + run.column, width,
                                residual + run.rows.first, 1.0, g + run.column);
  }
  // As Eigen maps: an element loop, which may not assume that the two
  // buffers are apart, adds one double at a time.
  using Segment = Eigen::Map<Eigen::VectorXd>;
  using ConstSegment = Eigen::Map<const Eigen::VectorXd>;
  Segment(gradient + local_dim_ + plan.global_begin, gc) += ConstSegment(g + lc, gc);
  if (lc > 0) Segment(gradient + groups_[plan.group].column + plan.local_begin, lc) += ConstSegment(g, lc);
  double* targets[3] = {a_.data(), b_.data(), c_.data()};
  for (int p = plan.product_begin; p < plan.product_end; ++p) {
    const RunProduct& product = products_[p];
    const double* rows = j + product.rows.first * width;
    add_transposed_product(depth(product.rows), product.width_a, product.width_b, rows + product.column_a, width,
                           rows + product.column_b, width, targets[product.target] + product.offset, product.stride,
                           1.0, product.upper);
  }
}

void SchurComplement::zero_group(int group) {
  const Group& g = groups_[group];
  std::fill_n(a_.data() + g.block, g.dim * g.dim, 0.0);
  std::fill_n(b_.data() + g.coupling, g.dim * (g.coupled_end - g.coupled_begin), 0.0);
  group_zeroed_[group] = 1;
}

void SchurComplement::accumulate(int slot, double* gradient) {
  // A group's blocks are zeroed when its first factor comes (a problem
  // lists a pose's factors together): they are still in cache when the
  // factor adds into them, where zeroing all of A and B first (several
  // times the first-level cache at a few dozen poses) would have
  // evicted them again.
  std::fill(group_zeroed_.begin(), group_zeroed_.end(), 0);
  std::fill(c_.begin(), c_.end(), 0.0);
  std::fill(gradient, gradient + columns(), 0.0);
  const BlockJacobian& lin = jacobian_;
  double* targets[3] = {a_.data(), b_.data(), c_.data()};
  for (int f = 0; f < lin.factor_count(); ++f) {
    const int group = factor_group_[f];
    if (group >= 0 && !group_zeroed_[group]) zero_group(group);
    if (plans_[f].gathered) {
      accumulate_gathered(slot, f, gradient);
      continue;
    }
    const int m = lin.residual_dim(f);
    lin.add_gradient(slot, f, gradient);
    for (int o = op_begin_[f]; o < op_begin_[f + 1]; ++o) {
      const BlockOp& op = ops_[o];
      const int da = lin.key_dim(f, op.a), db = lin.key_dim(f, op.b);
      const double* Ja = lin.jacobian(slot, f, op.a);
      const double* Jb = lin.jacobian(slot, f, op.b);
      op.kernel(m, da, db, Ja, Jb, targets[op.target] + op.offset, op.stride);
    }
  }
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    if (!group_zeroed_[g]) zero_group(static_cast<int>(g));
  }
}

FactorizationStatus SchurComplement::factorize(double radius, double min_diagonal, double max_diagonal,
                                               std::string* message) {
  const int n = global_dim_;
  std::copy(c_.begin(), c_.end(), s_.begin());
  for (int c = 0; c < n; ++c) {
    const std::size_t d = c + static_cast<std::size_t>(n) * c;
    s_[d] += std::clamp(c_[d], min_diagonal, max_diagonal) / radius;
  }
  // Every group's block first, then the eliminations: the blocks' Cholesky
  // chains (a square root and a reciprocal per column, each waiting for the
  // last) are independent of each other, so back to back they overlap.
  for (std::size_t gi = 0; gi < groups_.size(); ++gi) {
    const Group& g = groups_[gi];
    const int d = g.dim;
    const double* a = a_.data() + g.block;
    bool ok = false;
    for_group_dim(d, [&](auto size) {
      constexpr int D = decltype(size)::value;
      ok = factor_group<D>(d, a, factor_.data() + g.block, inverse_diagonal_.data() + g.column, radius, min_diagonal,
                           max_diagonal);
    });
    if (!ok) {
      bool finite = true;
      for (int k = 0; k < d * d; ++k) finite = finite && std::isfinite(a[k]);
      if (message) {
        *message = finite ? "matrix not positive definite (the block of pose group " + std::to_string(gi) + ")"
                          : "matrix entry of pose group " + std::to_string(gi) + " is not finite";
      }
      return finite ? FactorizationStatus::kNotPositiveDefinite : FactorizationStatus::kFatal;
    }
  }
  for (const Group& g : groups_) {
    eliminate_group(g.dim, factor_.data() + g.block, inverse_diagonal_.data() + g.column, b_.data() + g.coupling,
                    w_.data() + g.coupling, g.coupled_end - g.coupled_begin, coupled_.data() + g.coupled_begin,
                    g.first_if_contiguous(coupled_), s_.data(), n);
  }
  // S is dense (every pose reaches every global variable it is coupled to,
  // and the globals are few): an in-place dense Cholesky beats a sparse
  // factorisation's overhead at this size.
  for (int k = 0; k < n * n; ++k) {
    if (!std::isfinite(s_[k])) {
      if (message) *message = "reduced matrix entry " + std::to_string(k) + " is not finite";
      return FactorizationStatus::kFatal;
    }
  }
  if (!cholesky_upper<0>(s_.data(), n, reduced_inverse_diagonal_.data())) {
    if (message) *message = "matrix not positive definite (the reduced system over the global variables)";
    return FactorizationStatus::kNotPositiveDefinite;
  }
  return FactorizationStatus::kSuccess;
}

void SchurComplement::solve(const double* b, double* x) {
  const int n = global_dim_;
  std::copy(b + local_dim_, b + local_dim_ + n, reduced_rhs_.begin());
  double* x_global = x + local_dim_;
  for (const Group& g : groups_) {
    if (x != b) std::copy(b + g.column, b + g.column + g.dim, x + g.column);
    for_group_dim(g.dim, [&](auto size) {
      constexpr int D = decltype(size)::value;
      forward_group<D>(g.dim, factor_.data() + g.block, inverse_diagonal_.data() + g.column, w_.data() + g.coupling,
                       g.coupled_end - g.coupled_begin, coupled_.data() + g.coupled_begin,
                       g.first_if_contiguous(coupled_), x + g.column, reduced_rhs_.data());
    });
  }
  solve_reduced();
  std::copy(reduced_rhs_.begin(), reduced_rhs_.end(), x_global);
  for (const Group& g : groups_) {
    for_group_dim(g.dim, [&](auto size) {
      constexpr int D = decltype(size)::value;
      backward_group<D>(g.dim, factor_.data() + g.block, inverse_diagonal_.data() + g.column, w_.data() + g.coupling,
                        g.coupled_end - g.coupled_begin, coupled_.data() + g.coupled_begin,
                        g.first_if_contiguous(coupled_), x_global, x + g.column);
    });
  }
}

void SchurComplement::solve_global(const double* b_global, double* x_global) {
  const int n = global_dim_;
  // solve()'s forward pass over the groups subtracts W' U'^-1 b_l = +0 from
  // every entry: it leaves b_g as it is, so only the reduced solves remain.
  std::copy(b_global, b_global + n, reduced_rhs_.begin());
  solve_reduced();
  std::copy(reduced_rhs_.begin(), reduced_rhs_.end(), x_global);
}

void SchurComplement::solve_reduced() {
  const int n = global_dim_;
  solve_upper_transposed<0>(s_.data(), reduced_inverse_diagonal_.data(), n, reduced_rhs_.data());
  solve_upper<0>(s_.data(), reduced_inverse_diagonal_.data(), n, reduced_rhs_.data());
}

double SchurComplement::damping_quadratic(const double* x, double radius, double min_diagonal,
                                          double max_diagonal) const {
  double sum = 0.0;
  for (const Group& g : groups_) {
    const double* a = a_.data() + g.block;
    const double* xl = x + g.column;
    for (int j = 0; j < g.dim; ++j) {
      sum += std::clamp(a[j + g.dim * j], min_diagonal, max_diagonal) * xl[j] * xl[j];
    }
  }
  const int n = global_dim_;
  const double* x_global = x + local_dim_;
  for (int j = 0; j < n; ++j) {
    const double diagonal = c_[j + static_cast<std::size_t>(n) * j];
    sum += std::clamp(diagonal, min_diagonal, max_diagonal) * x_global[j] * x_global[j];
  }
  return sum / radius;
}

}  // namespace cdpr
