#include "solver/platform_statics.h"

#include <cmath>

#include <Eigen/LU>

namespace cdpr {
namespace {

using Mat3x = Eigen::Matrix<double, 3, kStaticsParamDim>;
using Mat6x = Eigen::Matrix<double, 6, kStaticsParamDim>;
using Wrench = Eigen::Matrix<double, 6, 1>;

const Eigen::Vector3d kUp = Eigen::Vector3d::UnitZ();

Eigen::Matrix3d skew3(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Per-cable geometry shared by the forces and the Jacobians.
struct CableGeometry {
  Eigen::Vector3d lever_world;  // r_i = R b_i
  Eigen::Vector3d s_c;          // horizontal unit vector anchor -> attachment
  double span = 0.0;
  Mat3x d_lever;  // d r_i / d x
  Mat3x d_s_c;    // d s_c / d x
};

// Wrench columns of J^T for one cable, Eq. (8): f_h acts along -s_c, f_v along +z.
Wrench column_h(const CableGeometry& g) {
  Wrench c;
  c << -g.s_c, -g.lever_world.cross(g.s_c);
  return c;
}
Wrench column_v(const CableGeometry& g) {
  Wrench c;
  c << kUp, g.lever_world.cross(kUp);
  return c;
}

}  // namespace

StaticsStatus solve_platform_statics(const Robot& robot, const StaticsInput& in, bool with_jacobian,
                                     std::array<CableStatics, kCableCount>& cables) {
  const Eigen::Matrix3d R = in.world_T_platform.world_R_platform.toRotationMatrix();
  const Eigen::Vector3d& p = in.world_T_platform.position_world;
  const int ref = robot.reference_cable;

  std::array<CableGeometry, kCableCount> geo;
  for (int i = 0; i < kCableCount; ++i) {
    const Eigen::Vector3d& b = robot.winches[i].attachment_platform;
    CableGeometry& g = geo[i];
    g.lever_world = R * b;
    const Eigen::Vector3d d = p + g.lever_world - in.anchor_world[i];
    g.span = std::hypot(d.x(), d.y());
    if (!(g.span > 1e-9)) return StaticsStatus::kVerticalCable;
    g.s_c = Eigen::Vector3d(d.x() / g.span, d.y() / g.span, 0.0);

    CableStatics& c = cables[i];
    c.span = g.span;
    c.anchor_z = in.anchor_world[i].z();
    c.attachment_z = p.z() + g.lever_world.z();
    if (!with_jacobian) continue;

    // d r / d theta = -R [b]x (right perturbation); d d = d p + d r - d a.
    g.d_lever.setZero();
    g.d_lever.block<3, 3>(0, kStaticsPose + 3) = -R * skew3(b);
    Mat3x d_d = g.d_lever;
    d_d.block<3, 3>(0, kStaticsPose) += Eigen::Matrix3d::Identity();
    d_d.block<3, 3>(0, kStaticsAnchor + 3 * i) -= Eigen::Matrix3d::Identity();
    // s_c = P d / |P d|  =>  d s_c = (P - s_c s_c^T) d d / L, with P = diag(1, 1, 0).
    Eigen::Matrix3d projector = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
    projector -= g.s_c * g.s_c.transpose();
    g.d_s_c = projector * d_d / g.span;

    c.d_span = g.s_c.transpose() * d_d;
    c.d_anchor_z.setZero();
    c.d_anchor_z(kStaticsAnchor + 3 * i + 2) = 1.0;
    c.d_attachment_z = d_d.row(2);
    c.d_attachment_z(kStaticsAnchor + 3 * i + 2) = 0.0;  // the attachment does not move with the anchor
  }

  // Eq. (6): the cables carry the weight, acting at the centre of mass.
  const double weight_n = robot.platform_mass_kg * robot.gravity_mps2;
  const Eigen::Vector3d com_world = R * (robot.center_of_mass_platform + in.com_offset_platform);
  Wrench w;
  w << weight_n * kUp, weight_n * com_world.cross(kUp);

  // Eq. (9)-(11): partition J^T into the reference cable and the rest.
  Eigen::Matrix<double, 6, 6> A;
  for (int i = 0, col = 0; i < kCableCount; ++i) {
    if (i == ref) continue;
    A.col(col++) = column_h(geo[i]);
    A.col(col++) = column_v(geo[i]);
  }
  const double f_h_ref = in.reference_force.x();
  const double f_v_ref = in.reference_force.y();
  const Wrench rhs = w - f_h_ref * column_h(geo[ref]) - f_v_ref * column_v(geo[ref]);
  const Eigen::PartialPivLU<Eigen::Matrix<double, 6, 6>> lu(A);
  // A is dimensionless in forces and metres in moments; a pivot this small
  // means two cables' planes coincide and Eq. (11) has no unique solution.
  if (!(std::abs(lu.determinant()) > 1e-12)) return StaticsStatus::kSingular;
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
  //   A d f_rest = d w - sum_i dW_i/dx|_f - J_ref d f_ref.
  // W_i = [F_i; r_i x F_i] with F_i = -f_h s_c + f_v z.
  Mat6x E = Mat6x::Zero();
  E.block<3, 3>(3, kStaticsPose + 3) = weight_n * skew3(kUp) * R * skew3(robot.center_of_mass_platform + in.com_offset_platform);
  E.block<3, 3>(3, kStaticsCom) = -weight_n * skew3(kUp) * R;
  for (int i = 0; i < kCableCount; ++i) {
    const CableGeometry& g = geo[i];
    const double f_h = cables[i].f_h;
    const Eigen::Vector3d force = -f_h * g.s_c + cables[i].f_v * kUp;
    E.topRows<3>() += f_h * g.d_s_c;
    E.bottomRows<3>() += skew3(force) * g.d_lever + f_h * skew3(g.lever_world) * g.d_s_c;
  }
  E.col(kStaticsForce) -= column_h(geo[ref]);
  E.col(kStaticsForce + 1) -= column_v(geo[ref]);
  const Mat6x d_f_rest = lu.solve(E);

  for (int i = 0, col = 0; i < kCableCount; ++i) {
    CableStatics& c = cables[i];
    if (i == ref) {
      c.d_f_h.setZero();
      c.d_f_v.setZero();
      c.d_f_h(kStaticsForce) = 1.0;
      c.d_f_v(kStaticsForce + 1) = 1.0;
    } else {
      c.d_f_h = d_f_rest.row(col++);
      c.d_f_v = d_f_rest.row(col++);
    }
  }
  return StaticsStatus::kOk;
}

}  // namespace cdpr
