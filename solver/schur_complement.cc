#include "solver/schur_complement.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <unordered_map>

#include <Eigen/Core>

#include "solver/dense_kernels.h"

namespace cdpr {
namespace {

bool is_per_pose(const Key& key) {
  return key.kind == VariableKind::kPose || key.kind == VariableKind::kReferenceForce;
}

// Dense kernels on one pose group's d x d blocks (column-major). D > 0 is d
// known at compile time (the loops unroll for the common group sizes),
// D = 0 takes the runtime `dim`.

// In-place Cholesky A = U'U of a block whose upper triangle holds A; false
// when A is not positive definite.
template <int D>
bool cholesky_upper(double* u, int dim) {
  const int d = D > 0 ? D : dim;
  for (int j = 0; j < d; ++j) {
    double* uj = u + d * j;
    for (int i = 0; i < j; ++i) {
      const double* ui = u + d * i;
      double s = uj[i];
      for (int p = 0; p < i; ++p) s -= ui[p] * uj[p];
      uj[i] = s / ui[i];
    }
    double s = uj[j];
    for (int p = 0; p < j; ++p) s -= uj[p] * uj[p];
    if (!(s > 0.0)) return false;
    uj[j] = std::sqrt(s);
  }
  return true;
}

// Solves U'y = b in place (forward substitution).
template <int D>
void solve_upper_transposed(const double* u, int dim, double* y) {
  const int d = D > 0 ? D : dim;
  for (int i = 0; i < d; ++i) {
    const double* ui = u + d * i;
    double s = y[i];
    for (int p = 0; p < i; ++p) s -= ui[p] * y[p];
    y[i] = s / ui[i];
  }
}

// Solves U x = b in place (back substitution).
template <int D>
void solve_upper(const double* u, int dim, double* x) {
  const int d = D > 0 ? D : dim;
  for (int i = d - 1; i >= 0; --i) {
    double s = x[i];
    for (int p = i + 1; p < d; ++p) s -= u[i + d * p] * x[p];
    x[i] = s / u[i + d * i];
  }
}

// B and W are d x m row-major (a row per local column, contiguous over the
// m coupled global columns), so the work below runs along contiguous rows.
// One group's part of the factorisation: U'U = A + D_A / radius,
// W = U'^-1 B and S -= W'W over its coupled columns (ascending, so into the
// upper triangle of the n x n S; `first` >= 0 when they are the contiguous
// columns first, first + 1, ...).
template <int D>
bool eliminate_group(int dim, const double* a, double* u, const double* b, double* w, int m, const int* columns,
                     int first, double* s, int n, double radius, double min_diagonal, double max_diagonal) {
  const int d = D > 0 ? D : dim;
  for (int j = 0; j < d; ++j) {
    for (int i = 0; i <= j; ++i) u[i + d * j] = a[i + d * j];
    u[j + d * j] += std::clamp(a[j + d * j], min_diagonal, max_diagonal) / radius;
  }
  if (!cholesky_upper<D>(u, d)) return false;
  solve_upper_transposed_rows(d, u, m, b, w);
  // S -= W'W (upper triangle).
  if (first >= 0) {
    add_transposed_product(d, m, m, w, m, w, m, s + first + static_cast<std::size_t>(n) * first, n, -1.0, true);
    return true;
  }
  for (int i = 0; i < d; ++i) {
    const double* wi = w + i * m;
    for (int q = 0; q < m; ++q) {
      double* s_column = s + static_cast<std::size_t>(n) * columns[q];
      for (int p = 0; p <= q; ++p) s_column[columns[p]] -= wi[p] * wi[q];
    }
  }
  return true;
}

// The group's part of a solve, before the reduced system: y = U'^-1 b_l in
// place, reduced right-hand side -= W'y (`first` as in eliminate_group).
template <int D>
void forward_group(int dim, const double* u, const double* w, int m, const int* columns, int first, double* y,
                   double* reduced) {
  const int d = D > 0 ? D : dim;
  solve_upper_transposed<D>(u, d, y);
  if (first >= 0) {
    add_transposed_times_vector(d, m, w, m, y, -1.0, reduced + first);
    return;
  }
  for (int i = 0; i < d; ++i) {
    for (int p = 0; p < m; ++p) reduced[columns[p]] -= w[i * m + p] * y[i];
  }
}

// ... and after it: x_l = U^-1 (y - W x_g) in place.
template <int D>
void backward_group(int dim, const double* u, const double* w, int m, const int* columns, int first,
                    const double* x_global, double* y) {
  const int d = D > 0 ? D : dim;
  if (first >= 0) {
    subtract_times_vector(d, m, w, m, x_global + first, y);
  } else {
    for (int i = 0; i < d; ++i) {
      double dot = 0.0;
      for (int p = 0; p < m; ++p) dot += w[i * m + p] * x_global[columns[p]];
      y[i] -= dot;
    }
  }
  solve_upper<D>(u, d, y);
}

// Calls f(std::integral_constant<int, D>) with D the group size when the
// kernels above are compiled for it (a pose with its reference force: 8; a
// pose alone: 6), else D = 0 (runtime size).
template <typename F>
void for_group_dim(int dim, F&& f) {
  switch (dim) {
    case 8: f(std::integral_constant<int, 8>{}); break;
    case 6: f(std::integral_constant<int, 6>{}); break;
    default: f(std::integral_constant<int, 0>{});
  }
}

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

std::unique_ptr<SchurComplement> SchurComplement::create(const Problem& problem) {
  const auto& variables = problem.variables();
  const int nv = static_cast<int>(variables.size());
  // Pose groups by pose index, in order of first appearance.
  std::vector<int> group_of(nv, -1);
  std::unordered_map<int, int> group_of_pose;
  std::vector<int> group_dim;
  int global_dim = 0;
  for (int v = 0; v < nv; ++v) {
    if (variables[v].constant) continue;
    if (!is_per_pose(variables[v].key)) {
      global_dim += variables[v].tangent_dim;
      continue;
    }
    const auto [it, inserted] = group_of_pose.emplace(variables[v].key.index, static_cast<int>(group_dim.size()));
    if (inserted) group_dim.push_back(0);
    group_of[v] = it->second;
    group_dim[it->second] += variables[v].tangent_dim;
    if (group_dim[it->second] > kMaxGroupDim) return nullptr;
  }
  if (group_dim.empty() || global_dim == 0 || global_dim > kMaxGlobalDim) return nullptr;
  for (const auto& factor : problem.factors()) {
    if (factor->keys().size() > 255) return nullptr;  // BlockOp holds key positions in a byte
    int group = -1;
    for (const Key& key : factor->keys()) {
      const int g = group_of[problem.variable_index(key)];
      if (g < 0) continue;
      if (group >= 0 && g != group) return nullptr;  // couples two poses: not block diagonal
      group = g;
    }
  }
  // Columns: each group's variables together (in variable order), then the globals.
  const int groups = static_cast<int>(group_dim.size());
  std::vector<int> next_column(groups, 0);
  int local_dim = 0;
  for (int g = 0; g < groups; ++g) {
    next_column[g] = local_dim;
    local_dim += group_dim[g];
  }
  std::vector<int> variable_column(nv, -1);
  int global_column = local_dim;
  for (int v = 0; v < nv; ++v) {
    if (variables[v].constant) continue;
    int& column = group_of[v] >= 0 ? next_column[group_of[v]] : global_column;
    variable_column[v] = column;
    column += variables[v].tangent_dim;
  }
  return std::unique_ptr<SchurComplement>(
      new SchurComplement(problem, std::move(variable_column), group_of, groups));
}

SchurComplement::SchurComplement(const Problem& problem, std::vector<int> variable_column,
                                 const std::vector<int>& group_of, int group_count)
    : linearization_(problem, std::move(variable_column)) {
  const auto& variables = problem.variables();
  const int nv = static_cast<int>(variables.size());
  const int nf = linearization_.factor_count();
  auto column_of = [&](int v) { return linearization_.variable_column(v); };

  // Group sizes and columns.
  groups_.assign(group_count, Group{});
  for (Group& g : groups_) g.column = -1;
  for (int v = 0; v < nv; ++v) {
    const int g = group_of[v];
    if (g < 0) {
      if (column_of(v) >= 0) global_dim_ += variables[v].tangent_dim;
      continue;
    }
    Group& group = groups_[g];
    group.column = group.column < 0 ? column_of(v) : std::min(group.column, column_of(v));
    group.dim += variables[v].tangent_dim;
    local_dim_ += variables[v].tangent_dim;
  }
  const int n = global_dim_;
  auto global_column = [&](int v) { return column_of(v) - local_dim_; };

  // The global variables each group's factors reach, and each factor's group.
  std::vector<std::vector<int>> coupled_variables(group_count);
  std::vector<int> factor_group(nf, -1);
  for (int f = 0; f < nf; ++f) {
    for (int k = 0; k < linearization_.key_count(f); ++k) {
      const int g = group_of[linearization_.key_variable(f, k)];
      if (g >= 0) factor_group[f] = g;
    }
    const int g = factor_group[f];
    if (g < 0) continue;
    for (int k = 0; k < linearization_.key_count(f); ++k) {
      const int v = linearization_.key_variable(f, k);
      if (group_of[v] < 0 && column_of(v) >= 0) coupled_variables[g].push_back(v);
    }
  }
  int block_total = 0, coupling_total = 0;
  for (int g = 0; g < group_count; ++g) {
    std::vector<int>& list = coupled_variables[g];
    std::sort(list.begin(), list.end(), [&](int x, int y) { return column_of(x) < column_of(y); });
    list.erase(std::unique(list.begin(), list.end()), list.end());
    Group& group = groups_[g];
    group.coupled_begin = static_cast<int>(coupled_.size());
    for (int v : list) {
      for (int d = 0; d < variables[v].tangent_dim; ++d) coupled_.push_back(global_column(v) + d);
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

  // Block operations of every factor: each pair of non-constant keys once,
  // oriented so the block lands in an upper triangle or in B.
  op_begin_.reserve(nf + 1);
  plans_.assign(nf, FactorPlan{});
  gather_column_.assign(linearization_.key_offset(nf), -1);
  std::size_t widest = 0, gathered_size = 0;
  for (int f = 0; f < nf; ++f) {
    op_begin_.push_back(static_cast<int>(ops_.size()));
    if (plan_gathered(f, factor_group[f], group_of)) {
      const FactorPlan& plan = plans_[f];
      const std::size_t width = plan.local_count + plan.global_count;
      widest = std::max(widest, width);
      gathered_size = std::max(gathered_size, width * linearization_.residual_dim(f));
      continue;
    }
    const int nk = linearization_.key_count(f);
    for (int a = 0; a < nk; ++a) {
      for (int b = a; b < nk; ++b) {
        int ka = a, kb = b;
        int va = linearization_.key_variable(f, ka), vb = linearization_.key_variable(f, kb);
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
        op.kernel = kernel_for(linearization_.key_dim(f, op.a), linearization_.key_dim(f, op.b));
        ops_.push_back(op);
      }
    }
  }
  op_begin_.push_back(static_cast<int>(ops_.size()));
  gathered_.assign(gathered_size, 0.0);
  gathered_gradient_.assign(widest, 0.0);
}

bool SchurComplement::plan_gathered(int f, int group, const std::vector<int>& group_of) {
  const Linearization& lin = linearization_;
  FactorPlan plan;
  plan.group = group;
  int local_end = 0, global_end = 0;
  bool any_local = false, any_global = false;
  for (int k = 0; k < lin.key_count(f); ++k) {
    const int v = lin.key_variable(f, k), column = lin.variable_column(v), d = lin.key_dim(f, k);
    if (column < 0) continue;
    if (group_of[v] >= 0) {
      const int begin = column - groups_[group].column;
      plan.local_begin = any_local ? std::min(plan.local_begin, begin) : begin;
      local_end = any_local ? std::max(local_end, begin + d) : begin + d;
      any_local = true;
    } else {
      const int begin = column - local_dim_;
      plan.global_begin = any_global ? std::min(plan.global_begin, begin) : begin;
      global_end = any_global ? std::max(global_end, begin + d) : begin + d;
      any_global = true;
    }
  }
  if (!any_local && !any_global) return false;
  // B's rows run over the group's coupled columns: the factor's global span
  // must be a run of them (true when they are contiguous: they include it).
  if (group >= 0 && any_global && !groups_[group].contiguous) return false;
  plan.local_count = any_local ? local_end - plan.local_begin : 0;
  plan.global_count = any_global ? global_end - plan.global_begin : 0;
  const int width = plan.local_count + plan.global_count;
  std::vector<bool> filled(width, false);
  for (int k = 0; k < lin.key_count(f); ++k) {
    const int v = lin.key_variable(f, k), column = lin.variable_column(v), d = lin.key_dim(f, k);
    if (column < 0) continue;
    const int first = group_of[v] >= 0 ? column - groups_[group].column - plan.local_begin
                                       : plan.local_count + column - local_dim_ - plan.global_begin;
    for (int c = first; c < first + d; ++c) {
      if (filled[c]) return false;  // a key listed twice
      filled[c] = true;
    }
    gather_column_[lin.key_offset(f) + k] = first;
  }
  plan.gaps = std::find(filled.begin(), filled.end(), false) != filled.end();
  plan.gathered = true;
  plans_[f] = plan;
  return true;
}

SchurComplement::~SchurComplement() = default;

void SchurComplement::accumulate_gathered(int slot, int f, double* gradient) {
  const Linearization& lin = linearization_;
  const FactorPlan& plan = plans_[f];
  const int m = lin.residual_dim(f), lc = plan.local_count, gc = plan.global_count, width = lc + gc;
  double* j = gathered_.data();
  if (plan.gaps) std::fill(j, j + m * width, 0.0);
  for (int k = 0; k < lin.key_count(f); ++k) {
    const int first = gather_column_[lin.key_offset(f) + k];
    if (first < 0) continue;
    const int d = lin.key_dim(f, k);
    const double* block = lin.jacobian(slot, f, k);
    // Rows of 1 to 6 values: a plain loop (std::copy calls memmove for each).
    for (int i = 0; i < m; ++i) {
      double* row = j + i * width + first;
      for (int c = 0; c < d; ++c) row[c] = block[i * d + c];
    }
  }
  // J^T r, then J^T J as its blocks A (local x local), B (local x global,
  // stored as its transpose, column-major) and C (global x global).
  double* g = gathered_gradient_.data();
  std::fill(g, g + width, 0.0);
  add_transposed_times_vector(m, width, j, width, lin.residuals(slot, f), 1.0, g);
  const int n = global_dim_;
  for (int c = 0; c < gc; ++c) gradient[local_dim_ + plan.global_begin + c] += g[lc + c];
  if (gc > 0) {
    add_transposed_product(m, gc, gc, j + lc, width, j + lc, width,
                           c_.data() + plan.global_begin + static_cast<std::size_t>(n) * plan.global_begin, n, 1.0,
                           true);
  }
  if (lc == 0) return;
  const Group& group = groups_[plan.group];
  for (int c = 0; c < lc; ++c) gradient[group.column + plan.local_begin + c] += g[c];
  add_transposed_product(m, lc, lc, j, width, j, width, a_.data() + group.block + plan.local_begin * (group.dim + 1),
                         group.dim, 1.0, true);
  if (gc > 0) {
    const int coupled = group.coupled_end - group.coupled_begin;
    const int position = plan.global_begin - group.first_if_contiguous(coupled_);
    add_transposed_product(m, gc, lc, j + lc, width, j, width,
                           b_.data() + group.coupling + position + coupled * plan.local_begin, coupled, 1.0, false);
  }
}

void SchurComplement::accumulate(int slot, double* gradient) {
  std::fill(a_.begin(), a_.end(), 0.0);
  std::fill(b_.begin(), b_.end(), 0.0);
  std::fill(c_.begin(), c_.end(), 0.0);
  std::fill(gradient, gradient + columns(), 0.0);
  const Linearization& lin = linearization_;
  double* targets[3] = {a_.data(), b_.data(), c_.data()};
  for (int f = 0; f < lin.factor_count(); ++f) {
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
}

FactorizationStatus SchurComplement::factorize(double radius, double min_diagonal, double max_diagonal,
                                               std::string* message) {
  const int n = global_dim_;
  std::copy(c_.begin(), c_.end(), s_.begin());
  for (int c = 0; c < n; ++c) {
    const std::size_t d = c + static_cast<std::size_t>(n) * c;
    s_[d] += std::clamp(c_[d], min_diagonal, max_diagonal) / radius;
  }
  for (std::size_t gi = 0; gi < groups_.size(); ++gi) {
    const Group& g = groups_[gi];
    const int d = g.dim, m = g.coupled_end - g.coupled_begin;
    const double* a = a_.data() + g.block;
    double* u = factor_.data() + g.block;
    const double* b = b_.data() + g.coupling;
    double* w = w_.data() + g.coupling;
    const int* columns = coupled_.data() + g.coupled_begin;
    const int first = g.first_if_contiguous(coupled_);
    bool ok = false;
    for_group_dim(d, [&](auto size) {
      constexpr int D = decltype(size)::value;
      ok = eliminate_group<D>(d, a, u, b, w, m, columns, first, s_.data(), n, radius, min_diagonal, max_diagonal);
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
  // S is dense (every pose reaches every global variable it is coupled to,
  // and the globals are few): an in-place dense Cholesky beats a sparse
  // factorisation's overhead at this size.
  for (int k = 0; k < n * n; ++k) {
    if (!std::isfinite(s_[k])) {
      if (message) *message = "reduced matrix entry " + std::to_string(k) + " is not finite";
      return FactorizationStatus::kFatal;
    }
  }
  if (!cholesky_upper<0>(s_.data(), n)) {
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
      forward_group<D>(g.dim, factor_.data() + g.block, w_.data() + g.coupling, g.coupled_end - g.coupled_begin,
                       coupled_.data() + g.coupled_begin, g.first_if_contiguous(coupled_), x + g.column,
                       reduced_rhs_.data());
    });
  }
  solve_upper_transposed<0>(s_.data(), n, reduced_rhs_.data());
  solve_upper<0>(s_.data(), n, reduced_rhs_.data());
  std::copy(reduced_rhs_.begin(), reduced_rhs_.end(), x_global);
  for (const Group& g : groups_) {
    for_group_dim(g.dim, [&](auto size) {
      constexpr int D = decltype(size)::value;
      backward_group<D>(g.dim, factor_.data() + g.block, w_.data() + g.coupling, g.coupled_end - g.coupled_begin,
                        coupled_.data() + g.coupled_begin, g.first_if_contiguous(coupled_), x_global, x + g.column);
    });
  }
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
