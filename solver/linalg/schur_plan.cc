// SchurComplement's plan, made once in its constructor: how each factor's
// J^T J reaches A, B and C, as a few dense products over runs of columns.
#include "solver/linalg/schur_complement.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace cdpr {
namespace {

// What summing J^T r and J^T J over runs costs, in multiply-adds plus a
// charge per kernel call (its set-up, loop control and the stores of its
// tiles: a few dozen instructions, as many as about 32 multiply-adds in the
// dense kernels). Rough on purpose: it only decides which runs to merge.
constexpr int kCallCost = 64;

}  // namespace

bool SchurComplement::plan_gathered(int f, int group, const std::vector<int>& group_of, RunCache& cache) {
  const BlockJacobian& lin = jacobian_;
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
  std::vector<unsigned char>& filled = cache.filled;
  std::vector<RowRange>& column_rows = cache.column_rows;
  filled.assign(width, 0);
  column_rows.assign(width, RowRange{});
  for (int k = 0; k < lin.key_count(f); ++k) {
    const int v = lin.key_variable(f, k), column = lin.variable_column(v), d = lin.key_dim(f, k);
    if (column < 0) continue;
    const int first = group_of[v] >= 0 ? column - groups_[group].column - plan.local_begin
                                       : plan.local_count + column - local_dim_ - plan.global_begin;
    for (int c = first; c < first + d; ++c) {
      if (filled[c]) return false;  // a key listed twice
      filled[c] = 1;
      column_rows[c] = lin.key_rows(f, k);
    }
    gather_column_[lin.key_offset(f) + k] = first;
  }
  plan.gaps = std::find(filled.begin(), filled.end(), 0) != filled.end();
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

}  // namespace cdpr
