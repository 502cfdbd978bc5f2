#include "solver/model/platform_statics.h"

#include <cmath>
#include <utility>

namespace cdpr {
namespace {

using Wrench = Eigen::Matrix<double, 6, 1>;

const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

// Per-cable geometry shared by the forces and the Jacobians.
struct CableGeometry {
  Eigen::Vector3d lever_world;  // r_i = R b_i
  Eigen::Vector3d s_c;          // horizontal unit vector anchor -> attachment
  double span = 0.0;
};

// out = f(a x b) entry by entry, each entry as Eigen's cross computes it.
// Assigning a.cross(b) (or f of it) to part of a vector instead goes
// through a temporary stored an entry at a time and reloaded two at a
// time: a load the CPU cannot forward from those stores, so it waits for
// them to reach the cache, in the statics' hottest loops.
template <typename Out, typename F>
void set_cross(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Out&& out, F f) {
  out(0) = f(a.y() * b.z() - a.z() * b.y());
  out(1) = f(a.z() * b.x() - a.x() * b.z());
  out(2) = f(a.x() * b.y() - a.y() * b.x());
}
template <typename Out>
void set_cross(const Eigen::Vector3d& a, const Eigen::Vector3d& b, Out&& out) {
  set_cross(a, b, out, [](double x) { return x; });
}

// Wrench columns of J^T for one cable, Eq. (8): f_h acts along -s_c, f_v
// along +z. Written in place (a column of A or a Wrench), in fixed-size
// segments: Eigen's comma initializer and a returned temporary each cost
// more than the arithmetic, which runs for every statics evaluation.
template <typename Column>
void write_column_h(const CableGeometry& g, Column&& c) {
  c.template head<3>() = -g.s_c;
  set_cross(g.lever_world, g.s_c, c.template tail<3>(), [](double x) { return -x; });
}
template <typename Column>
void write_column_v(const CableGeometry& g, Column&& c) {
  c.template head<3>() = kUp;
  set_cross(g.lever_world, kUp, c.template tail<3>());
}

// LU with partial pivoting of the 6x6 matrix of Eq. (11), in plain loops:
// the statics solve it for one right-hand side and, with Jacobians, a dozen
// more, where a generic blocked solver costs more than the arithmetic.
class Lu6 {
 public:
  explicit Lu6(const Eigen::Matrix<double, 6, 6>& a) {
#pragma GCC unroll 6
    for (int r = 0; r < 6; ++r) {
#pragma GCC unroll 6
      for (int c = 0; c < 6; ++c) lu_[r][c] = a(r, c);
    }
    eliminate<0>();
  }
  double determinant() const { return determinant_; }
  // A^-1 b for one right-hand side (a Wrench) or, row-major, N of them at
  // once: each step of the substitutions is then one row operation over
  // all N (vectorised), fewer operations than N separate solves or an
  // explicit inverse times b.
  template <typename Rhs>
  Rhs solve(const Rhs& b) const {
    static_assert(Rhs::RowsAtCompileTime == 6 && (Rhs::ColsAtCompileTime == 1 || Rhs::IsRowMajor));
    Rhs x;
#pragma GCC unroll 6
    for (int r = 0; r < 6; ++r) {
      x.row(r) = b.row(row_of_[r]);
#pragma GCC unroll 6
      for (int c = 0; c < r; ++c) x.row(r) -= lu_[r][c] * x.row(c);
    }
#pragma GCC unroll 6
    for (int r = 5; r >= 0; --r) {
#pragma GCC unroll 6
      for (int c = r + 1; c < 6; ++c) x.row(r) -= lu_[r][c] * x.row(c);
      x.row(r) *= inverse_diagonal_[r];
    }
    return x;
  }

 private:
  // Column K of the elimination and, recursively, the ones after it: the
  // column index a compile-time constant, so every loop below has fixed
  // bounds and unrolls completely, with no loop control left.
  template <int K>
  void eliminate() {
    if constexpr (K < 6) {
      int pivot = K;
#pragma GCC unroll 6
      for (int r = K + 1; r < 6; ++r) {
        if (std::abs(lu_[r][K]) > std::abs(lu_[pivot][K])) pivot = r;
      }
      if (pivot != K) {
        std::swap(row_of_[K], row_of_[pivot]);
#pragma GCC unroll 6
        for (int c = 0; c < 6; ++c) std::swap(lu_[K][c], lu_[pivot][c]);
        determinant_ = -determinant_;
      }
      const double diagonal = lu_[K][K];
      determinant_ *= diagonal;
      if (diagonal == 0.0) {  // singular: determinant 0, the caller refuses
        inverse_diagonal_[K] = 0.0;
      } else {
        inverse_diagonal_[K] = 1.0 / diagonal;
#pragma GCC unroll 6
        for (int r = K + 1; r < 6; ++r) {
          const double factor = lu_[r][K] * inverse_diagonal_[K];
          lu_[r][K] = factor;
#pragma GCC unroll 6
          for (int c = K + 1; c < 6; ++c) lu_[r][c] -= factor * lu_[K][c];
        }
      }
      eliminate<K + 1>();
    }
  }

  double lu_[6][6];
  double inverse_diagonal_[6];
  int row_of_[6] = {0, 1, 2, 3, 4, 5};  // row r of P A is row row_of_[r] of A
  double determinant_ = 1.0;
};

// Geometry of every cable, the weight's wrench and the 6x6 matrix of Eq. (11)
// at one pose; kOk or why the statics are undefined there.
struct Setup {
  Eigen::Matrix3d R;
  std::array<CableGeometry, kCableCount> geo;
  Eigen::Vector3d com_platform;
  Wrench w;
  Eigen::Matrix<double, 6, 6> A;
  Wrench column_h_ref, column_v_ref;
};

StaticsStatus set_up(const Robot& robot, const StaticsInput& in, Setup& s,
                     std::array<double, kCableCount>* span, std::array<double, kCableCount>* anchor_z,
                     std::array<double, kCableCount>* attachment_z) {
  s.R = in.world_T_platform.world_R_platform.toRotationMatrix();
  const Eigen::Vector3d& p = in.world_T_platform.position_world;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d& b = robot.winches[i].attachment_platform;
    CableGeometry& g = s.geo[i];
    // lazyProduct: the same sums as `*`, which here calls an out-of-line product.
    g.lever_world = s.R.lazyProduct(b);
    const Eigen::Vector3d d = p + g.lever_world - in.anchor_world[i];
    // Spans are metres: their squares neither overflow nor underflow, so
    // the plain root is exact enough and costs far less than std::hypot.
    g.span = std::sqrt(d.x() * d.x() + d.y() * d.y());
    if (!(g.span > 1e-9)) return StaticsStatus::kVerticalCable;
    g.s_c = Eigen::Vector3d(d.x() / g.span, d.y() / g.span, 0.0);
    (*span)[i] = g.span;
    (*anchor_z)[i] = in.anchor_world[i].z();
    (*attachment_z)[i] = p.z() + g.lever_world.z();
  }

  // Eq. (6): the cables carry the weight, acting at the centre of mass.
  const double weight_n = robot.platform_mass_kg * robot.gravity_mps2;
  s.com_platform = robot.center_of_mass_platform + in.com_offset_platform;
  const Eigen::Vector3d com_world = s.R.lazyProduct(s.com_platform);
  s.w.head<3>() = weight_n * kUp;
  set_cross(com_world, kUp, s.w.tail<3>(), [weight_n](double x) { return weight_n * x; });

  // Eq. (9)-(11): partition J^T into the reference cable and the rest.
  const int ref = robot.reference_cable;
  for (int i = 0, col = 0; i < kCableCount; ++i) {
    if (i == ref) continue;
    write_column_h(s.geo[i], s.A.col(col++));
    write_column_v(s.geo[i], s.A.col(col++));
  }
  write_column_h(s.geo[ref], s.column_h_ref);
  write_column_v(s.geo[ref], s.column_v_ref);
  return StaticsStatus::kOk;
}

// A is dimensionless in forces and metres in moments; a pivot this small
// means two cables' planes coincide and Eq. (11) has no unique solution.
bool singular(const Lu6& lu) { return !(std::abs(lu.determinant()) > 1e-12); }

// Eigen fills a whole matrix with a constant by std::fill_n, a scalar loop
// of 23 stores here; through a block view the same zeros are an unrolled,
// vectorised assignment.
inline void set_zero(StaticsRow& row) { row.segment<kStaticsParamDim>(0).setZero(); }

// The right-hand sides of the statics Jacobian (see solve_platform_statics)
// by column: u_0..3, rotation (3), centre of mass (3), reference force (2).
constexpr int kU = 0, kRotation = 4, kCom = 7, kForce = 10;
using RightHandSides = Eigen::Matrix<double, 6, 12, Eigen::RowMajor>;

// One row of d f_rest over the statics parameters from its row of
// G = A^-1 E (see solve_platform_statics): the rank-one terms v_i phi_i in
// the horizontal position, rotation and anchor (x, y) columns, G's own
// blocks in the rotation, reference-force and centre-of-mass columns, and
// zero in the columns the forces do not depend on (height, anchor heights).
// Every entry is written, so the row needs no zero fill first.
void write_force_derivative_row(const RightHandSides& g, int rest,
                                const std::array<Eigen::Matrix<double, 1, 7>, kCableCount>& phi, StaticsRow& row) {
  double d_x = 0.0, d_y = 0.0;
  Eigen::Matrix<double, 1, 3> d_rotation = g.block<1, 3>(rest, kRotation);
#pragma GCC unroll 4
  for (int i = 0; i < kCableCount; ++i) {
    const double v = g(rest, kU + i);
    const int anchor = kStaticsAnchor + 3 * i;
    d_x += v * phi[i](0);
    d_y += v * phi[i](1);
    d_rotation += v * phi[i].segment<3>(2);
    row(anchor) = v * phi[i](5);
    row(anchor + 1) = v * phi[i](6);
    row(anchor + 2) = 0.0;
  }
  row(kStaticsPose) = d_x;
  row(kStaticsPose + 1) = d_y;
  row(kStaticsPose + 2) = 0.0;
  row.segment<3>(kStaticsPose + 3) = d_rotation;
  row.segment<2>(kStaticsForce) = g.block<1, 2>(rest, kForce);
  row.segment<3>(kStaticsCom) = g.block<1, 3>(rest, kCom);
}

}  // namespace

StaticsStatus reference_force_map(const Robot& robot, const StaticsInput& in, ReferenceForceMap& map) {
  Setup s;
  if (const StaticsStatus status = set_up(robot, in, s, &map.span, &map.anchor_z, &map.attachment_z);
      status != StaticsStatus::kOk) {
    return status;
  }
  const Lu6 lu(s.A);
  if (singular(lu)) return StaticsStatus::kSingular;
  // A^-1 (for d_force_d_yaw) and A^-1 [w, J_h,ref, J_v,ref] in one pass.
  Eigen::Matrix<double, 6, 9, Eigen::RowMajor> b;
  b.leftCols<6>().setIdentity();
  b.col(6) = s.w;
  b.col(7) = s.column_h_ref;
  b.col(8) = s.column_v_ref;
  const Eigen::Matrix<double, 6, 9, Eigen::RowMajor> x = lu.solve(b);
  map.inverse = x.leftCols<6>();
  const Wrench offset = x.col(6);
  const Wrench gain_h = -x.col(7), gain_v = -x.col(8);
  map.reference = robot.reference_cable;
  for (int i = 0, col = 0; i < kCableCount; ++i) {
    const CableGeometry& g = s.geo[i];
    map.lever[i] = g.lever_world;
    map.s_c[i] = g.s_c;
    map.t[i] = Eigen::Vector3d(-g.s_c.y(), g.s_c.x(), 0.0);
    // d d / d yaw = z x r: the attachment swings round the vertical.
    map.d_span_d_yaw[i] = g.s_c.dot(kUp.cross(g.lever_world));
    if (i == robot.reference_cable) {
      map.offset[i].setZero();
      map.gain[i].setIdentity();
      continue;
    }
    map.offset[i] = offset.segment<2>(col);
    map.gain[i].col(0) = gain_h.segment<2>(col);
    map.gain[i].col(1) = gain_v.segment<2>(col);
    col += 2;
  }
  // w = [W z; W c x z] with c = R c_p turning too: d/d yaw = [0; W (z x c) x z].
  const double weight_n = robot.platform_mass_kg * robot.gravity_mps2;
  const Eigen::Vector3d com_world = s.R * s.com_platform;
  map.d_weight_d_yaw << Eigen::Vector3d::Zero(), weight_n * kUp.cross(com_world).cross(kUp);
  return StaticsStatus::kOk;
}

std::array<Eigen::Vector2d, kCableCount> ReferenceForceMap::d_force_d_yaw(const Eigen::Vector2d& f) const {
  // As in solve_platform_statics' Jacobian, for the single direction of a
  // turn about the vertical: d r = z x r, d s_c = t phi with
  // phi = t' (z x r) / L, and E = d w - sum_i dW_i/d yaw at fixed forces.
  Wrench e = d_weight_d_yaw;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector2d fi = offset[i] + gain[i] * f;
    const Eigen::Vector3d d_lever = kUp.cross(lever[i]);
    const double phi = t[i].dot(d_lever) / span[i];
    const Eigen::Vector3d force = -fi.x() * s_c[i] + fi.y() * kUp;
    e.head<3>() += fi.x() * phi * t[i];
    e.tail<3>() += force.cross(d_lever) + fi.x() * phi * lever[i].cross(t[i]);
  }
  const Wrench d_rest = inverse * e;
  std::array<Eigen::Vector2d, kCableCount> d;
  for (int i = 0, col = 0; i < kCableCount; ++i) {
    if (i == reference) {
      d[i].setZero();
      continue;
    }
    d[i] = d_rest.segment<2>(col);
    col += 2;
  }
  return d;
}

StaticsStatus solve_platform_statics(const Robot& robot, const StaticsInput& in, bool with_jacobian,
                                     std::array<CableStatics, kCableCount>& cables) {
  const int ref = robot.reference_cable;
  Setup s;
  std::array<double, kCableCount> span, anchor_z, attachment_z;
  if (const StaticsStatus status = set_up(robot, in, s, &span, &anchor_z, &attachment_z);
      status != StaticsStatus::kOk) {
    return status;
  }
  for (int i = 0; i < kCableCount; ++i) {
    cables[i].span = span[i];
    cables[i].anchor_z = anchor_z[i];
    cables[i].attachment_z = attachment_z[i];
  }
  const Eigen::Matrix3d& R = s.R;
  const std::array<CableGeometry, kCableCount>& geo = s.geo;
  const Eigen::Vector3d& com_platform = s.com_platform;
  const Wrench& column_h_ref = s.column_h_ref;
  const Wrench& column_v_ref = s.column_v_ref;
  const double weight_n = robot.platform_mass_kg * robot.gravity_mps2;
  const double f_h_ref = in.reference_force.x();
  const double f_v_ref = in.reference_force.y();
  const Wrench rhs = s.w - f_h_ref * column_h_ref - f_v_ref * column_v_ref;
  const Lu6 lu(s.A);
  if (singular(lu)) return StaticsStatus::kSingular;
  const Wrench f_rest = lu.solve(rhs);

  for (int i = 0, col = 0; i < kCableCount; ++i) {
    if (i == ref) {
      cables[i].f_h = f_h_ref;
      cables[i].f_v = f_v_ref;
    } else {
      cables[i].f_h = f_rest(col++);
      cables[i].f_v = f_rest(col++);
    }
  }
  if (!with_jacobian) return StaticsStatus::kOk;

  // Implicit differentiation of sum_i W_i(f_i, x) = w(x):
  //   A d f_rest = E = d w - sum_i dW_i/dx|_f - J_ref d f_ref,
  // W_i = [F_i; r_i x F_i] with F_i = -f_h s_c + f_v z. With d = p + r - a
  // and t = z x s_c, the horizontal direction moves as d s_c = t phi,
  // phi = t' d d / L (rank one, as P - s_c s_c' = t t' for P = diag(1, 1, 0)),
  // and d r = -R [b]x d theta. So E is a sum of outer products u_i phi_i,
  // u_i = f_h [t; r x t], plus blocks in the rotation, centre-of-mass and
  // reference-force columns: a dozen solves with A instead of one per column.
  // The right-hand sides, solved together in one pass of the LU.
  RightHandSides e;  // every entry written below; these are the only zeros:
  e.block<3, 6>(0, kRotation).setZero();
  // d r_i = -R [b_i]x d theta, so a' d r_i / d theta = (b_i x R'a)' for any
  // world vector a. The rotation block, weight [z]x R [c]x - sum_i [F_i]x R [b_i]x,
  // is R N with N = weight [z_p]x [c]x - sum_i [R'F_i]x [b_i]x (as
  // [a]x R = R [R'a]x) and [u]x [v]x = v u' - (u'v) I: outer products in the
  // platform frame and one 3x3 product, instead of two per cable.
  const Eigen::Vector3d up_platform = R.row(2).transpose();  // z_p = R'z
  Eigen::Matrix3d n = weight_n * (com_platform * up_platform.transpose());
  n.diagonal().array() -= weight_n * up_platform.dot(com_platform);
  std::array<Eigen::Vector3d, kCableCount> s_c_platform;  // R's_c
  std::array<Eigen::Matrix<double, 1, 7>, kCableCount> phi;  // over (p_x, p_y, theta (3), a_x, a_y)
  for (int i = 0; i < kCableCount; ++i) {
    const CableGeometry& g = geo[i];
    const Eigen::Vector3d& b = robot.winches[i].attachment_platform;
    const Eigen::Vector3d t(-g.s_c.y(), g.s_c.x(), 0.0);
    s_c_platform[i] = R.transpose() * g.s_c;
    const Eigen::Vector3d t_platform = R.transpose() * t;
    const double f_h = cables[i].f_h;
    const Eigen::Vector3d force_platform = -f_h * s_c_platform[i] + cables[i].f_v * up_platform;
    phi[i](0) = t.x() / g.span;
    phi[i](1) = t.y() / g.span;
    set_cross(b, t_platform, phi[i].segment<3>(2), [&g](double x) { return x / g.span; });
    phi[i](5) = -t.x() / g.span;
    phi[i](6) = -t.y() / g.span;
    e.col(kU + i).head<3>() = f_h * t;
    e.col(kU + i).tail<3>() = f_h * g.lever_world.cross(t);
    n.noalias() -= b * force_platform.transpose();  // by columns, no temporary (see set_cross)
    n.diagonal().array() += force_platform.dot(b);
  }
  e.block<3, 3>(3, kRotation) = R * n;
  // -weight [z]x R: z x (R v) = (-(R v)_y, (R v)_x, 0).
  e.block<1, 3>(3, kCom) = weight_n * R.row(1);
  e.block<1, 3>(4, kCom) = -weight_n * R.row(0);
  e.block<1, 3>(5, kCom).setZero();
  e.col(kForce) = -column_h_ref;
  e.col(kForce + 1) = -column_v_ref;
  const RightHandSides solved = lu.solve(e);  // G = A^-1 E, v_i = A^-1 u_i in its first columns

  for (int i = 0, col = 0; i < kCableCount; ++i) {
    CableStatics& c = cables[i];
    const CableGeometry& g = geo[i];
    const int anchor = kStaticsAnchor + 3 * i;
    // span = |P d|: d span = s_c' d d.
    set_zero(c.d_span);
    c.d_span(kStaticsPose) = g.s_c.x();
    c.d_span(kStaticsPose + 1) = g.s_c.y();
    set_cross(robot.winches[i].attachment_platform, s_c_platform[i], c.d_span.segment<3>(kStaticsPose + 3));
    c.d_span(anchor) = -g.s_c.x();
    c.d_span(anchor + 1) = -g.s_c.y();
    set_zero(c.d_anchor_z);
    c.d_anchor_z(anchor + 2) = 1.0;
    // The attachment moves with the pose, not with the anchor.
    set_zero(c.d_attachment_z);
    c.d_attachment_z(kStaticsPose + 2) = 1.0;
    set_cross(robot.winches[i].attachment_platform, up_platform, c.d_attachment_z.segment<3>(kStaticsPose + 3));
    if (i == ref) {
      set_zero(c.d_f_h);
      set_zero(c.d_f_v);
      c.d_f_h(kStaticsForce) = 1.0;
      c.d_f_v(kStaticsForce + 1) = 1.0;
    } else {
      write_force_derivative_row(solved, col++, phi, c.d_f_h);
      write_force_derivative_row(solved, col++, phi, c.d_f_v);
    }
  }
  return StaticsStatus::kOk;
}

}  // namespace cdpr
