#include "solver/linalg/sparse_cholesky.h"

#include <cholmod.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace cdpr {
namespace {

[[noreturn]] void die(const char* what) {
  std::fprintf(stderr, "cdpr::SparseCholesky: %s\n", what);
  std::abort();
}

// CHOLMOD reports through Common.status; the handler only keeps it quiet.
void quiet_error_handler(int, const char*, int, const char*) {}

}  // namespace

// Why the permutation is done here and not by CHOLMOD: cholmod_factorize on a
// non-natural ordering builds P A P' in a freshly allocated matrix on every
// call, and the supernodal kernel allocates its update matrix on every call.
// A simplicial LL' factor of an upper-triangular matrix already in fill-
// reducing order factorizes in place (cholmod_rowfac on S = A), so the
// constructor computes the AMD order once, stores the permuted pattern, and
// factorize() scatters the caller's values through a fixed index map.
struct SparseCholesky::Impl {
  cholmod_common common;
  int n = 0;
  int nnz = 0;
  std::vector<int> permuted_index;  // caller's value k -> entry of the permuted matrix
  std::vector<int> perm;            // row perm[k] of A is row k of P A P'
  std::vector<int> diagonal;        // caller's value index of each diagonal entry, -1 if absent
  cholmod_sparse* matrix = nullptr; // P A P', upper triangle, stype > 0
  cholmod_factor* factor = nullptr;
  cholmod_dense* rhs = nullptr;
  cholmod_dense* solution = nullptr;
  cholmod_dense* work_y = nullptr;
  cholmod_dense* work_e = nullptr;
  bool factorized = false;

  Impl() {
    cholmod_start(&common);
    common.print = 0;
    common.error_handler = quiet_error_handler;
  }
  ~Impl() {
    cholmod_free_dense(&rhs, &common);
    cholmod_free_dense(&solution, &common);
    cholmod_free_dense(&work_y, &common);
    cholmod_free_dense(&work_e, &common);
    cholmod_free_factor(&factor, &common);
    cholmod_free_sparse(&matrix, &common);
    cholmod_finish(&common);
  }
};

SparseCholesky::SparseCholesky(int n, std::vector<int> column_starts, std::vector<int> row_indices)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  if (n <= 0 || static_cast<int>(column_starts.size()) != n + 1 || column_starts[0] != 0 ||
      column_starts[n] != static_cast<int>(row_indices.size())) {
    die("pattern sizes do not match");
  }
  s.n = n;
  s.nnz = column_starts[n];
  s.diagonal.assign(n, -1);
  for (int c = 0; c < n; ++c) {
    for (int k = column_starts[c]; k < column_starts[c + 1]; ++k) {
      const int r = row_indices[k];
      if (r < 0 || r > c || (k > column_starts[c] && row_indices[k - 1] >= r)) {
        die("pattern not upper triangular with sorted rows");
      }
      if (r == c) s.diagonal[c] = k;
    }
  }
  cholmod_common& cm = s.common;

  // 1. AMD order of the caller's pattern (values unused).
  cholmod_sparse original{};
  original.nrow = original.ncol = n;
  original.nzmax = s.nnz;
  original.p = column_starts.data();
  original.i = row_indices.data();
  original.stype = 1;
  original.itype = CHOLMOD_INT;
  original.xtype = CHOLMOD_PATTERN;
  original.dtype = CHOLMOD_DOUBLE;
  original.sorted = 1;
  original.packed = 1;
  cm.nmethods = 1;
  cm.method[0].ordering = CHOLMOD_AMD;
  cm.supernodal = CHOLMOD_SIMPLICIAL;
  cholmod_factor* ordering = cholmod_analyze(&original, &cm);
  if (ordering == nullptr) die("symbolic analysis failed (out of memory?)");
  const int* p = static_cast<const int*>(ordering->Perm);
  s.perm.assign(p, p + n);
  cholmod_free_factor(&ordering, &cm);
  std::vector<int> inverse(n);
  for (int k = 0; k < n; ++k) inverse[s.perm[k]] = k;

  // 2. Pattern of P A P' (upper), and where each caller's value lands in it.
  std::vector<int> count(n + 1, 0);
  for (int c = 0; c < n; ++c) {
    for (int k = column_starts[c]; k < column_starts[c + 1]; ++k) {
      const int a = inverse[row_indices[k]], b = inverse[c];
      ++count[std::max(a, b) + 1];
    }
  }
  for (int c = 0; c < n; ++c) count[c + 1] += count[c];
  s.matrix = cholmod_allocate_sparse(n, n, s.nnz, 1, 1, 1, CHOLMOD_REAL, &cm);
  if (s.matrix == nullptr) die("out of memory");
  int* mp = static_cast<int*>(s.matrix->p);
  int* mi = static_cast<int*>(s.matrix->i);
  for (int c = 0; c <= n; ++c) mp[c] = count[c];
  std::vector<int> next(count.begin(), count.end() - 1);
  s.permuted_index.assign(s.nnz, -1);
  std::vector<std::vector<std::pair<int, int>>> by_column(n);  // (row, caller index)
  for (int c = 0; c < n; ++c) {
    for (int k = column_starts[c]; k < column_starts[c + 1]; ++k) {
      const int a = inverse[row_indices[k]], b = inverse[c];
      by_column[std::max(a, b)].push_back({std::min(a, b), k});
    }
  }
  for (int c = 0; c < n; ++c) {
    std::sort(by_column[c].begin(), by_column[c].end());
    for (const auto& [row, k] : by_column[c]) {
      mi[next[c]] = row;
      s.permuted_index[k] = next[c]++;
    }
  }

  // 3. Symbolic analysis of P A P' in natural order (no postorder: that
  // would be a second permutation CHOLMOD applies only when it copies).
  cm.method[0].ordering = CHOLMOD_NATURAL;
  cm.postorder = 0;
  cm.final_ll = 1;  // LL' so an indefinite matrix fails instead of giving a negative D
  s.factor = cholmod_analyze(s.matrix, &cm);
  if (s.factor == nullptr || s.factor->ordering != CHOLMOD_NATURAL || s.factor->is_super) {
    die("natural-order simplicial analysis failed");
  }

  // 4. One numeric factorisation and solve of the identity so that L's values,
  // CHOLMOD's workspace and the solve buffers exist before the first real call.
  s.rhs = cholmod_zeros(n, 1, CHOLMOD_REAL, &cm);
  if (s.rhs == nullptr) die("out of memory");
  std::vector<double> identity(s.nnz, 0.0);
  for (int c = 0; c < n; ++c) {
    if (s.diagonal[c] < 0) die("pattern lacks a diagonal entry");
    identity[s.diagonal[c]] = 1.0;
  }
  std::string message;
  if (factorize(identity.data(), &message) != FactorizationStatus::kSuccess) die(message.c_str());
  solve(identity.data(), identity.data());  // first n entries are a fine right-hand side
  s.factorized = false;
}

SparseCholesky::~SparseCholesky() = default;

int SparseCholesky::size() const { return impl_->n; }
int SparseCholesky::nonzeros() const { return impl_->nnz; }

FactorizationStatus SparseCholesky::factorize(const double* values, std::string* message) {
  Impl& s = *impl_;
  s.factorized = false;
  double* x = static_cast<double*>(s.matrix->x);
  for (int k = 0; k < s.nnz; ++k) {
    if (!std::isfinite(values[k])) {
      if (message) *message = "matrix entry " + std::to_string(k) + " is not finite";
      return FactorizationStatus::kFatal;
    }
    x[s.permuted_index[k]] = values[k];
  }
  cholmod_factorize(s.matrix, s.factor, &s.common);
  switch (s.common.status) {
    case CHOLMOD_OK:
    case CHOLMOD_DSMALL:  // LL' never produces it with the default dbound
      s.factorized = true;
      return FactorizationStatus::kSuccess;
    case CHOLMOD_NOT_POSDEF:
      if (message) {
        const int minor = static_cast<int>(s.factor->minor);
        *message = "matrix not positive definite (leading minor of order " + std::to_string(minor + 1) +
                   " in fill-reducing order, original column " + std::to_string(s.perm[minor]) + ")";
      }
      return FactorizationStatus::kNotPositiveDefinite;
    case CHOLMOD_OUT_OF_MEMORY:
      if (message) *message = "CHOLMOD out of memory";
      return FactorizationStatus::kFatal;
    default:
      if (message) *message = "CHOLMOD failure, status " + std::to_string(s.common.status);
      return FactorizationStatus::kFatal;
  }
}

void SparseCholesky::solve(const double* b, double* x) {
  Impl& s = *impl_;
  if (!s.factorized) die("solve() without a successful factorize()");
  double* rhs = static_cast<double*>(s.rhs->x);
  for (int k = 0; k < s.n; ++k) rhs[k] = b[s.perm[k]];
  // solution/work_y/work_e are reused when their shapes match what
  // cholmod_solve2 asks for. The simplicial solve leaves work_y shaped by the
  // number of right-hand sides (1 x n) although it asks for 4 x n on the next
  // call, which would free and reallocate it every time; restore the shape
  // it was allocated with (tests/solver/nls/lm_allocation_test.cc watches this).
  if (s.work_y != nullptr && s.work_y->nzmax >= 4 * static_cast<std::size_t>(s.n)) {
    s.work_y->nrow = 4;
    s.work_y->d = 4;
  }
  if (!cholmod_solve2(CHOLMOD_A, s.factor, s.rhs, nullptr, &s.solution, nullptr, &s.work_y, &s.work_e, &s.common)) {
    die("cholmod_solve2 failed");
  }
  const double* y = static_cast<const double*>(s.solution->x);
  for (int k = 0; k < s.n; ++k) x[s.perm[k]] = y[k];
}

}  // namespace cdpr
