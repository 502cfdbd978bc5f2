#pragma once
// The normal equations of a block-sparse Jacobian whose variables can be
// eliminated group by group (Ceres' SPARSE_SCHUR in spirit): the
// elimination order (elimination_order.h) puts variables into small "local"
// groups that no factor shares with another group (in a calibration: the
// variables of one static pose); everything else (anchors, offsets, model
// terms) is "global". Then
//
//   [ A   B ] [x_l]   [b_l]        S = C - B' A^-1 B   (reduced matrix)
//   [ B'  C ] [x_g] = [b_g],       S x_g = b_g - B' A^-1 b_l,
//                                   x_l = A^-1 (b_l - B x_g),
//
// with A block diagonal (one dense block per group, Cholesky in place) and S
// over the global variables only (at most kMaxGlobalDim of them), dense and
// factorised in place by a dense Cholesky: every pose couples all the
// globals it reaches, so S has (nearly) no zeros to exploit, and at 16 to
// 128 columns a sparse factorisation costs more in overhead than in
// arithmetic. An iteration costs O(groups) small dense operations plus one
// factorisation of S, whatever the number of groups.
//
// Everything is sized in the constructor, in time linear in the number of
// factor keys; accumulate(), factorize() and solve() allocate nothing. The
// Jacobian must outlive this object and keep its structure.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "solver/linalg/block_jacobian.h"
#include "solver/linalg/elimination_order.h"
#include "solver/linalg/sparse_cholesky.h"

namespace cdpr {

class SchurComplement {
 public:
  // Null when the Jacobian lacks the structure: no group or no global
  // variable, a factor touching two groups' variables, a group larger than
  // kMaxGroupDim or more than kMaxGlobalDim global dimensions (then the
  // whole J^T J in CHOLMOD is the better system to factorise: the dense S
  // grows as the cube of its columns). Otherwise assigns the Jacobian's
  // columns: each group's variables together (in variable order), then the
  // kept ones in the order's `kept` order.
  static constexpr int kMaxGroupDim = 16;
  static constexpr int kMaxGlobalDim = 128;
  static std::unique_ptr<SchurComplement> create(BlockJacobian& jacobian, const EliminationOrder& order);
  ~SchurComplement();

  int columns() const { return local_dim_ + global_dim_; }  // the groups' columns first, then global ones
  int local_columns() const { return local_dim_; }
  int variable_column(int v) const { return jacobian_.variable_column(v); }

  // J^T J (kept inside) and J^T r (into `gradient`, columns() values) of `slot`.
  void accumulate(int slot, double* gradient);
  // Factorises J^T J + D / radius, D = diag(J^T J) clamped to
  // [min_diagonal, max_diagonal]; radius = infinity for J^T J itself.
  FactorizationStatus factorize(double radius, double min_diagonal, double max_diagonal, std::string* message);
  // x = (J^T J + D / radius)^-1 b with the last successful factorisation; x may alias b.
  void solve(const double* b, double* x);
  // The global part of solve() for a b whose local part is zero:
  // x_g = S^-1 b_g (b_g and x_g: the global columns' values, may alias),
  // the same values solve() gives there, without the groups' work.
  void solve_global(const double* b_global, double* x_global);
  // x' D x / radius, the damping factorize(radius, ...) added: what the LM
  // loop needs for the model decrease of a step.
  double damping_quadratic(const double* x, double radius, double min_diagonal, double max_diagonal) const;

  // out(r, c) += sum_i Ja(i, r) Jb(i, c) for row-major m x da and m x db blocks.
  using BlockKernel = void (*)(int m, int da, int db, const double* ja, const double* jb, double* out, int stride);

 private:
  struct Group {
    int column = 0;        // first (local) column
    int dim = 0;
    int block = 0;         // offset of its dim x dim block in a_ and factor_
    int coupling = 0;      // offset of its dim x coupled block in b_ and w_
    int coupled_begin = 0; // into coupled_: the global columns its poses' factors reach, ascending
    int coupled_end = 0;
    bool contiguous = false;  // coupled columns are consecutive
    // The first coupled column when they are consecutive, else -1.
    int first_if_contiguous(const std::vector<int>& coupled) const {
      if (!contiguous) return -1;
      return coupled_end > coupled_begin ? coupled[coupled_begin] : 0;
    }
  };
  // One block J_a' J_b of a factor's keys a, b added into `target` at
  // `offset` (column-major, leading dimension `stride`).
  enum Target : unsigned char { kLocal, kCoupling, kGlobal };
  struct BlockOp {
    unsigned char a, b;
    Target target;
    int offset;
    int stride;
    BlockKernel kernel;  // compiled for (da, db) when they are common sizes
  };

  // How a factor's J^T J reaches A, B and C. Gathered: its Jacobian blocks
  // are copied into one row-major residual_dim x width matrix whose columns
  // are a span of its group's local columns, then a span of global ones, so
  // its whole J^T J is a few dense products written in place (the usual
  // case). Otherwise (a global span its group does not reach contiguously,
  // a key listed twice): one block product per pair of keys (ops_).
  struct FactorPlan {
    bool gathered = false;
    int group = -1;                          // -1: no per-pose key
    int local_begin = 0, local_count = 0;    // within the group's columns
    int global_begin = 0, global_count = 0;  // among the global columns
    bool gaps = false;                       // some gathered column no key fills (kept zero)
    int run_begin = 0, run_end = 0;          // into runs_
    int product_begin = 0, product_end = 0;  // into products_
  };
  // Consecutive gathered columns read over the same rows: the hull of their
  // keys' Factor::jacobian_rows (outside it they are zero). J^T r and J^T J
  // are summed over those rows only: a pose factor's offsets reach one row
  // each and its load-cell row the reference force alone.
  struct ColumnRun {
    int column = 0, width = 0;  // within the gathered row
    RowRange rows;
  };
  // One block of a gathered factor's J^T J: runs a and b over the rows both
  // reach, added into A, B or C at `offset` with leading dimension `stride`.
  struct RunProduct {
    int column_a = 0, width_a = 0, column_b = 0, width_b = 0;
    RowRange rows;
    Target target = kLocal;
    bool upper = false;  // a run with itself: the upper triangle
    int offset = 0, stride = 0;
  };
  // What planning the factors one after another carries over: the splits
  // into runs found so far, by the split they started from (a handful:
  // every pose has the same few kinds of factor), and scratch, so planning
  // a thousand poses allocates next to nothing.
  struct RunCache {
    std::vector<std::pair<std::vector<ColumnRun>, std::vector<ColumnRun>>> splits;
    // Per gathered column: 1 when a key fills it (bytes, not vector<bool>:
    // cheaper to set and to test).
    std::vector<unsigned char> filled;
    std::vector<RowRange> column_rows;   // per gathered column: its key's rows (none for a gap)
    std::vector<ColumnRun> initial;
  };

  // group_of[v]: the pose group of variable v, -1 for global or constant ones.
  // Plans the gathered J^T J of factor f (false: it takes block ops).
  bool plan_gathered(int f, int group, const std::vector<int>& group_of, RunCache& cache);
  // Splits factor f's gathered columns (their rows: cache.column_rows) into
  // runs and lists their products.
  void plan_runs(int f, RunCache& cache);
  static int runs_cost(const std::vector<ColumnRun>& runs);
  static std::vector<ColumnRun> merge_runs(std::vector<ColumnRun> runs, int local_count);
  void accumulate_gathered(int slot, int f, double* gradient);
  // Zeroes group g's blocks of A and B (the first thing accumulate() does to them).
  void zero_group(int g);
  // reduced_rhs_ = S^-1 reduced_rhs_ with the last factorisation of S.
  void solve_reduced();
  SchurComplement(const BlockJacobian& jacobian, const std::vector<int>& group_of, int group_count);

  const BlockJacobian& jacobian_;
  int local_dim_ = 0, global_dim_ = 0;
  std::vector<Group> groups_;
  std::vector<int> coupled_;             // global columns (0-based among the globals)
  // The strictly lower triangles of a_, c_ and s_ are scratch (the dense
  // kernels may write there); only upper triangles are read.
  std::vector<double> a_, factor_;       // per group: J^T J block (upper), its damped Cholesky factor U (A = U'U)
  std::vector<double> b_, w_;            // per group, row-major: coupling block B, then W = U'^-1 B
  std::vector<double> c_, s_;            // global x global, column-major upper: C, then the reduced S
  std::vector<double> inverse_diagonal_;          // per local column: 1 / U_jj of its group's factor
  std::vector<double> reduced_inverse_diagonal_;  // 1 / diagonal of S's factor
  std::vector<FactorPlan> plans_;        // per factor
  std::vector<int> factor_group_;        // per factor: the group of its local keys, -1 for none
  std::vector<unsigned char> group_zeroed_;  // per group: its blocks zeroed in this accumulate()
  std::vector<ColumnRun> runs_;
  std::vector<RunProduct> products_;
  std::vector<int> gather_column_;       // per factor key (the Jacobian's order): column in the gathered row, -1 if constant
  std::vector<double> gathered_, gathered_gradient_;  // scratch of the widest gathered factor
  std::vector<BlockOp> ops_;             // of the factors not gathered, in order
  std::vector<int> op_begin_;            // per factor into ops_ (+1 at the end)
  std::vector<double> reduced_rhs_;
};

}  // namespace cdpr
