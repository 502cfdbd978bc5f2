#pragma once
// The variables and factors of one calibration problem. Owns both; the
// solver reads and updates variable values in place.
//
// Invariants (checked, abort with a message when broken): a key is added
// once; every key a factor names exists when the factor is added and appears
// once in that factor. Adding a variable or factor changes the structure, so
// it must not happen while a LevenbergMarquardt refers to the problem.

#include <map>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "solver/linalg/elimination_order.h"
#include "solver/nls/factor.h"
#include "solver/nls/keys.h"
#include "solver/nls/pose.h"

namespace cdpr {

// The retraction the solver applies (Problem::retract) on one variable's
// ambient storage: a pose (7 values, x y z qw qx qy qz) by pose.h's retract,
// a vector by adding the step.
void retract_ambient(bool is_pose, int ambient_dim, const double* step, double* ambient);

class Problem {
 public:
  void add_pose(Key key, const Pose& value);                  // tangent 6, ambient 7
  void add_vector(Key key, const Eigen::VectorXd& value);     // Euclidean
  void set_constant(Key key, bool constant = true);           // held fixed by the solver
  void add_factor(std::unique_ptr<Factor> factor);            // keys must exist

  bool has(Key key) const { return find(key) >= 0; }
  Pose pose(Key key) const;
  Eigen::VectorXd vector(Key key) const;
  void set_pose(Key key, const Pose& value);
  void set_vector(Key key, const Eigen::VectorXd& value);

  struct Variable {
    Key key;
    int tangent_dim = 0;
    int ambient_dim = 0;
    int ambient_offset = 0;  // into state()
    bool is_pose = false;
    bool constant = false;
  };
  const std::vector<Variable>& variables() const { return variables_; }
  // Index into variables(); aborts on an unknown key. O(1).
  int variable_index(Key key) const;
  const std::vector<std::unique_ptr<Factor>>& factors() const { return factors_; }

  // Flat ambient state of all variables, in variables() order.
  std::vector<double>& state() { return state_; }
  const std::vector<double>& state() const { return state_; }
  // Applies a tangent step to variable v (pose: retract; others: add).
  void retract(int v, const double* step);
  // The same on another flat state of this problem's layout (the solver's
  // candidate copy); allocates nothing.
  void retract(int v, const double* step, double* state) const;

  // Which variables the linear systems eliminate first: the variables of
  // one static pose (PoseKey(k), ReferenceForceKey(k)), which no factor
  // shares with another pose, form a group (groups in order of first
  // appearance); the others are kept, by key, so the variables of one kind
  // sit side by side (all anchors, then all offsets, ...). Constant
  // variables take no part.
  EliminationOrder elimination_order() const;

 private:
  void add_variable(Key key, int tangent_dim, int ambient_dim, bool is_pose, const double* value);
  const Variable& checked(Key key, bool is_pose) const;  // aborts on an unknown key or wrong kind
  int find(Key key) const;                               // variable index, -1 if unknown

  std::vector<Variable> variables_;
  // Key -> variable index: a flat table per kind for the dense small indices
  // every problem uses (pose k, cable i, ...), a map for any other index.
  static constexpr int kDenseIndexLimit = 1 << 20;
  std::vector<std::vector<int>> dense_index_;  // [kind][index], -1 where absent
  std::map<Key, int> sparse_index_;
  std::vector<double> state_;
  std::vector<std::unique_ptr<Factor>> factors_;
};

}  // namespace cdpr
