#include "solver/nls/schur_complement.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <unordered_map>

#include <Eigen/Core>

#include "solver/linalg/dense_kernels.h"

namespace cdpr {
namespace {

bool is_per_pose(const Key& key) {
  return key.kind == VariableKind::kPose || key.kind == VariableKind::kReferenceForce;
}

// Dense kernels on one pose group's d x d blocks (column-major). D > 0 is d
// known at compile time (the loops unroll for the common group sizes),
// D = 0 takes the runtime `dim`.

// In-place Cholesky A = U'U of a block whose upper triangle holds A, and
// the reciprocals of U's diagonal into `inverse` (every solve with U
// multiplies by them: a division costs as much as a dozen multiply-adds and
// sits on the critical path of each substitution); false when A is not
// positive definite.
template <int D>
bool cholesky_upper(double* u, int dim, double* inverse) {
  const int d = D > 0 ? D : dim;
  for (int j = 0; j < d; ++j) {
    double* uj = u + d * j;
    for (int i = 0; i < j; ++i) {
      const double* ui = u + d * i;
      double s = uj[i];
      for (int p = 0; p < i; ++p) s -= ui[p] * uj[p];
      uj[i] = s * inverse[i];
    }
    double s = uj[j];
    for (int p = 0; p < j; ++p) s -= uj[p] * uj[p];
    if (!(s > 0.0)) return false;
    uj[j] = std::sqrt(s);
    inverse[j] = 1.0 / uj[j];
  }
  return true;
}

// Solves U'y = b in place (forward substitution).
template <int D>
void solve_upper_transposed(const double* u, const double* inverse, int dim, double* y) {
  const int d = D > 0 ? D : dim;
  for (int i = 0; i < d; ++i) {
    const double* ui = u + d * i;
    double s = y[i];
    for (int p = 0; p < i; ++p) s -= ui[p] * y[p];
    y[i] = s * inverse[i];
  }
}

// Solves U x = b in place (back substitution).
template <int D>
void solve_upper(const double* u, const double* inverse, int dim, double* x) {
  const int d = D > 0 ? D : dim;
  for (int i = d - 1; i >= 0; --i) {
    double s = x[i];
    for (int p = i + 1; p < d; ++p) s -= u[i + d * p] * x[p];
    x[i] = s * inverse[i];
  }
}

// One group's damped block factorised: U'U = A + D_A / radius, in place of
// its copy in u; false when not positive definite.
template <int D>
bool factor_group(int dim, const double* a, double* u, double* inverse, double radius, double min_diagonal,
                  double max_diagonal) {
  const int d = D > 0 ? D : dim;
  for (int j = 0; j < d; ++j) {
    for (int i = 0; i <= j; ++i) u[i + d * j] = a[i + d * j];
    u[j + d * j] += std::clamp(a[j + d * j], min_diagonal, max_diagonal) / radius;
  }
  return cholesky_upper<D>(u, d, inverse);
}

// B and W are d x m row-major (a row per local column, contiguous over the
// m coupled global columns), so the work below runs along contiguous rows.
// One group's elimination once U is known: W = U'^-1 B and S -= W'W over
// its coupled columns (ascending, so into the upper triangle of the n x n
// S; `first` >= 0 when they are the contiguous columns first, first + 1, ...).
void eliminate_group(int d, const double* u, const double* inverse, const double* b, double* w, int m,
                     const int* columns, int first, double* s, int n) {
  solve_upper_transposed_rows(d, u, inverse, m, b, w);
  // S -= W'W (upper triangle).
  if (first >= 0) {
    add_transposed_product(d, m, m, w, m, w, m, s + first + static_cast<std::size_t>(n) * first, n, -1.0, true);
    return;
  }
  for (int i = 0; i < d; ++i) {
    const double* wi = w + i * m;
    for (int q = 0; q < m; ++q) {
      double* s_column = s + static_cast<std::size_t>(n) * columns[q];
      for (int p = 0; p <= q; ++p) s_column[columns[p]] -= wi[p] * wi[q];
    }
  }
}

// The group's part of a solve, before the reduced system: y = U'^-1 b_l in
// place, reduced right-hand side -= W'y (`first` as in eliminate_group).
template <int D>
void forward_group(int dim, const double* u, const double* inverse, const double* w, int m, const int* columns,
                   int first, double* y, double* reduced) {
  const int d = D > 0 ? D : dim;
  solve_upper_transposed<D>(u, inverse, d, y);
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
void backward_group(int dim, const double* u, const double* inverse, const double* w, int m, const int* columns,
                    int first, const double* x_global, double* y) {
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
  solve_upper<D>(u, inverse, d, y);
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

// dst(i, c) = block(i, c) for a row-major m x d block into rows of stride
// `ld`: d fixed for the tangent sizes that occur (D > 0), so each row is a
// few moves (a generic loop, or std::copy's memmove per row, cost several
// times more than the values); D = 0 takes the runtime `dim`.
template <int D>
void copy_block_columns(int m, int dim, const double* block, double* dst, int ld) {
  const int d = D > 0 ? D : dim;
  for (int i = 0; i < m; ++i) {
    for (int c = 0; c < d; ++c) dst[i * ld + c] = block[i * d + c];
  }
}
void copy_block_columns(int m, int d, const double* block, double* dst, int ld) {
  switch (d) {
    case 1: return copy_block_columns<1>(m, d, block, dst, ld);
    case 2: return copy_block_columns<2>(m, d, block, dst, ld);
    case 3: return copy_block_columns<3>(m, d, block, dst, ld);
    case 6: return copy_block_columns<6>(m, d, block, dst, ld);
    default: return copy_block_columns<0>(m, d, block, dst, ld);
  }
}

int depth(RowRange r) { return std::max(0, r.end - r.first); }
bool same_rows(RowRange a, RowRange b) { return a.first == b.first && a.end == b.end; }
RowRange common_rows(RowRange a, RowRange b) { return {std::max(a.first, b.first), std::min(a.end, b.end)}; }
RowRange hull(RowRange a, RowRange b) {
  if (depth(a) == 0) return b;
  if (depth(b) == 0) return a;
  return {std::min(a.first, b.first), std::max(a.end, b.end)};
}

// What summing J^T r and J^T J over runs costs, in multiply-adds plus a
// charge per kernel call (its set-up, loop control and the stores of its
// tiles: a few dozen instructions, as many as about 32 multiply-adds in the
// dense kernels). Rough on purpose: it only decides which runs to merge.
constexpr int kCallCost = 64;

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
  // Columns: each group's variables together (in variable order), then the
  // globals by key, so the variables of one kind sit side by side (all
  // anchors, then all offsets, ...): a pose factor's Jacobian columns of a
  // kind share their zero rows (Factor::jacobian_rows), and side by side
  // they make one run of its J^T J.
  const int groups = static_cast<int>(group_dim.size());
  std::vector<int> next_column(groups, 0);
  int local_dim = 0;
  for (int g = 0; g < groups; ++g) {
    next_column[g] = local_dim;
    local_dim += group_dim[g];
  }
  std::vector<int> variable_column(nv, -1), globals;
  for (int v = 0; v < nv; ++v) {
    if (variables[v].constant) continue;
    if (group_of[v] < 0) {
      globals.push_back(v);
      continue;
    }
    variable_column[v] = next_column[group_of[v]];
    next_column[group_of[v]] += variables[v].tangent_dim;
  }
  std::stable_sort(globals.begin(), globals.end(),
                   [&](int a, int b) { return variables[a].key < variables[b].key; });
  int global_column = local_dim;
  for (int v : globals) {
    variable_column[v] = global_column;
    global_column += variables[v].tangent_dim;
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
  inverse_diagonal_.assign(local_dim_, 0.0);
  reduced_inverse_diagonal_.assign(n, 0.0);

  // Block operations of every factor: each pair of non-constant keys once,
  // oriented so the block lands in an upper triangle or in B.
  op_begin_.reserve(nf + 1);
  plans_.assign(nf, FactorPlan{});
  gather_column_.assign(linearization_.key_offset(nf), -1);
  std::size_t widest = 0, gathered_size = 0;
  RunCache run_cache;
  for (int f = 0; f < nf; ++f) {
    op_begin_.push_back(static_cast<int>(ops_.size()));
    if (plan_gathered(f, factor_group[f], group_of, run_cache)) {
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

bool SchurComplement::plan_gathered(int f, int group, const std::vector<int>& group_of, RunCache& cache) {
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
  std::vector<bool>& filled = cache.filled;
  std::vector<RowRange>& column_rows = cache.column_rows;
  filled.assign(width, false);
  column_rows.assign(width, RowRange{});
  for (int k = 0; k < lin.key_count(f); ++k) {
    const int v = lin.key_variable(f, k), column = lin.variable_column(v), d = lin.key_dim(f, k);
    if (column < 0) continue;
    const int first = group_of[v] >= 0 ? column - groups_[group].column - plan.local_begin
                                       : plan.local_count + column - local_dim_ - plan.global_begin;
    for (int c = first; c < first + d; ++c) {
      if (filled[c]) return false;  // a key listed twice
      filled[c] = true;
      column_rows[c] = lin.key_rows(f, k);
    }
    gather_column_[lin.key_offset(f) + k] = first;
  }
  plan.gaps = std::find(filled.begin(), filled.end(), false) != filled.end();
  plan.gathered = true;
  plans_[f] = plan;
  plan_runs(f, cache);
  return true;
}

int SchurComplement::runs_cost(const std::vector<ColumnRun>& runs) {
  int cost = 0;
  for (std::size_t a = 0; a < runs.size(); ++a) {
    if (depth(runs[a].rows) > 0) cost += runs[a].width * depth(runs[a].rows) + kCallCost;
    for (std::size_t b = a; b < runs.size(); ++b) {
      const int d = depth(common_rows(runs[a].rows, runs[b].rows));
      if (d == 0) continue;
      const int entries = a == b ? runs[a].width * (runs[a].width + 1) / 2 : runs[a].width * runs[b].width;
      cost += entries * d + kCallCost;
    }
  }
  return cost;
}

// Merges neighbouring runs of the same part (per-pose or global columns)
// while that makes the sums cheaper: runs over the same rows always (one
// call instead of three, the same multiply-adds), a narrow run next to a
// deep one not (its zeros would be summed over the deep one's rows).
std::vector<SchurComplement::ColumnRun> SchurComplement::merge_runs(std::vector<ColumnRun> runs, int local_count) {
  auto merge = [](std::vector<ColumnRun>& r, std::size_t i) {
    r[i].width += r[i + 1].width;
    r[i].rows = hull(r[i].rows, r[i + 1].rows);
    r.erase(r.begin() + static_cast<std::ptrdiff_t>(i) + 1);
  };
  for (;;) {
    int best = runs_cost(runs);
    std::size_t best_at = runs.size();
    for (std::size_t i = 0; i + 1 < runs.size(); ++i) {
      if ((runs[i].column < local_count) != (runs[i + 1].column < local_count)) continue;
      std::vector<ColumnRun> merged = runs;
      merge(merged, i);
      if (const int cost = runs_cost(merged); cost < best) {
        best = cost;
        best_at = i;
      }
    }
    if (best_at == runs.size()) return runs;
    merge(runs, best_at);
  }
}

void SchurComplement::plan_runs(int f, RunCache& cache) {
  FactorPlan& plan = plans_[f];
  const int width = plan.local_count + plan.global_count;
  // Neighbouring columns of the same part and rows form a run to start
  // with; those are merged further unless a factor before had the same
  // columns and rows (the usual case: every pose has the same factors).
  std::vector<ColumnRun>& initial = cache.initial;
  initial.clear();
  for (int c = 0; c < width; ++c) {
    const RowRange rows = cache.column_rows[c];
    if (!initial.empty() && c != plan.local_count && same_rows(initial.back().rows, rows)) {
      ++initial.back().width;
    } else {
      initial.push_back({c, 1, rows});
    }
  }
  auto same_split = [](const std::vector<ColumnRun>& a, const std::vector<ColumnRun>& b) {
    return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const ColumnRun& x, const ColumnRun& y) {
      return x.column == y.column && x.width == y.width && same_rows(x.rows, y.rows);
    });
  };
  auto& splits = cache.splits;
  auto known = std::find_if(splits.begin(), splits.end(), [&](const auto& split) {
    return same_split(split.first, initial);
  });
  plan.run_begin = static_cast<int>(runs_.size());
  if (known != splits.end()) {
    runs_.insert(runs_.end(), known->second.begin(), known->second.end());
  } else {
    const std::vector<ColumnRun> merged = merge_runs(initial, plan.local_count);
    runs_.insert(runs_.end(), merged.begin(), merged.end());
    // A problem of many kinds of factor would make this search long.
    constexpr std::size_t kRememberedSplits = 16;
    if (splits.size() < kRememberedSplits) splits.emplace_back(initial, merged);
  }
  plan.run_end = static_cast<int>(runs_.size());

  // Their products, each landing in an upper triangle (A, C) or in B.
  const int n = global_dim_;
  plan.product_begin = static_cast<int>(products_.size());
  for (int a = plan.run_begin; a < plan.run_end; ++a) {
    for (int b = a; b < plan.run_end; ++b) {
      const ColumnRun& x = runs_[a];
      const ColumnRun& y = runs_[b];
      const RowRange rows = common_rows(x.rows, y.rows);
      if (depth(rows) == 0) continue;
      const bool local_x = x.column < plan.local_count, local_y = y.column < plan.local_count;
      if (local_x && local_y) {
        const Group& group = groups_[plan.group];
        products_.push_back({x.column, x.width, y.column, y.width, rows, kLocal, a == b,
                             group.block + (plan.local_begin + x.column) + group.dim * (plan.local_begin + y.column),
                             group.dim});
      } else if (!local_x && !local_y) {
        const int gx = plan.global_begin + x.column - plan.local_count;
        const int gy = plan.global_begin + y.column - plan.local_count;
        products_.push_back({x.column, x.width, y.column, y.width, rows, kGlobal, a == b, gx + n * gy, n});
      } else {
        // B, stored as its transpose (column-major, leading dimension the
        // group's coupled count): the global run's rows, the local run's columns.
        const ColumnRun& global = local_x ? y : x;
        const ColumnRun& local = local_x ? x : y;
        const Group& group = groups_[plan.group];
        const int coupled = group.coupled_end - group.coupled_begin;
        const int position = plan.global_begin - group.first_if_contiguous(coupled_) + global.column - plan.local_count;
        products_.push_back({global.column, global.width, local.column, local.width, rows, kCoupling, false,
                             group.coupling + position + coupled * (plan.local_begin + local.column), coupled});
      }
    }
  }
  plan.product_end = static_cast<int>(products_.size());
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
  for (int c = 0; c < gc; ++c) gradient[local_dim_ + plan.global_begin + c] += g[lc + c];
  if (lc > 0) {
    const int first = groups_[plan.group].column + plan.local_begin;
    for (int c = 0; c < lc; ++c) gradient[first + c] += g[c];
  }
  double* targets[3] = {a_.data(), b_.data(), c_.data()};
  for (int p = plan.product_begin; p < plan.product_end; ++p) {
    const RunProduct& product = products_[p];
    const double* rows = j + product.rows.first * width;
    add_transposed_product(depth(product.rows), product.width_a, product.width_b, rows + product.column_a, width,
                           rows + product.column_b, width, targets[product.target] + product.offset, product.stride,
                           1.0, product.upper);
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
  solve_upper_transposed<0>(s_.data(), reduced_inverse_diagonal_.data(), n, reduced_rhs_.data());
  solve_upper<0>(s_.data(), reduced_inverse_diagonal_.data(), n, reduced_rhs_.data());
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
