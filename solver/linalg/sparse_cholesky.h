#pragma once
// Cholesky factorisation of a symmetric positive definite sparse matrix of a
// fixed pattern (compressed sparse column, upper triangle). Contract (after
// Ceres' sparse_cholesky.h): the symbolic analysis is done once in the
// constructor; factorize() refactorises numerically and solve() back-solves,
// both reusing all memory sized at construction: neither allocates (the
// constructor runs one factorisation and solve so CHOLMOD's lazily allocated
// parts exist). cholmod.h appears only in the implementation.
//
// Implementation: AMD order computed once, the matrix stored permuted, and a
// simplicial LL' factor (an indefinite matrix fails instead of producing a
// negative pivot). Every column must have its diagonal entry in the pattern.
// solve() before a successful factorize() aborts.

#include <memory>
#include <string>
#include <vector>

namespace cdpr {

enum class FactorizationStatus {
  kSuccess,
  kNotPositiveDefinite,  // raise the damping and try again
  kFatal,                // out of memory or a broken pattern: give up
};

class SparseCholesky {
 public:
  // column_starts: n+1 entries; row_indices: sorted per column, rows <= column.
  SparseCholesky(int n, std::vector<int> column_starts, std::vector<int> row_indices);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  int size() const;
  int nonzeros() const;
  // values: one per stored entry, in the pattern's order.
  FactorizationStatus factorize(const double* values, std::string* message);
  // Solves A x = b with the last successful factorisation; x may alias b.
  void solve(const double* b, double* x);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cdpr
