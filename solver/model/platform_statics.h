#pragma once
// Static equilibrium of the platform on four heavy cables with one reference
// cable (paper Eq. (5)-(11)): given the pose, the reference cable's force and
// the anchors, the other three cables' forces follow from the 6x6 system of
// Eq. (11). Also yields each cable's catenary inputs (span, heights).
//
// Jacobians are taken with respect to the local parameter vector
//   x = [d_p (3), d_theta (3), f_ref (2), anchor_0..3 (12), com_offset (3)]
// where (d_p, d_theta) is the pose's tangent perturbation (solver/nls/pose.h).
// Allocation-free.

#include <array>

#include <Eigen/Core>

#include "solver/nls/pose.h"
#include "solver/model/robot.h"

namespace cdpr {

inline constexpr int kStaticsParamDim = 23;
inline constexpr int kStaticsPose = 0;
inline constexpr int kStaticsForce = 6;
inline constexpr int kStaticsAnchor = 8;  // + 3 * cable
inline constexpr int kStaticsCom = 20;

using StaticsRow = Eigen::Matrix<double, 1, kStaticsParamDim>;

// One cable in its vertical plane (paper Sec. III-A).
struct CableStatics {
  double f_h = 0.0;           // [N] horizontal force on the platform, towards the anchor
  double f_v = 0.0;           // [N] vertical force on the platform, up positive
  double span = 0.0;          // [m] L_i, horizontal anchor-attachment distance
  double anchor_z = 0.0;      // [m]
  double attachment_z = 0.0;  // [m] world height of the attachment point
  // Rows over the statics parameters. The geometry's reach few columns,
  // whatever the forces: the span's the pose's and this cable's own
  // anchor's, the anchor height's that anchor's alone, the attachment
  // height's the pose's alone; zero elsewhere (StaticPoseFactor sums only
  // the rows that reach a block).
  StaticsRow d_f_h, d_f_v, d_span, d_anchor_z, d_attachment_z;
};

struct StaticsInput {
  Pose world_T_platform;
  Eigen::Vector2d reference_force = Eigen::Vector2d::Zero();  // (f_h, f_v) [N]
  std::array<Eigen::Vector3d, kCableCount> anchor_world;
  Eigen::Vector3d com_offset_platform = Eigen::Vector3d::Zero();  // [m] added to the nominal CoM
};

enum class StaticsStatus {
  kOk,
  kVerticalCable,  // a cable's span is ~0: its vertical plane is undefined
  kSingular,       // the partition of Eq. (9) is singular at this pose
};

// Fills `cables` (forces of all four, reference included). Jacobian rows are
// filled only when `with_jacobian`.
StaticsStatus solve_platform_statics(const Robot& robot, const StaticsInput& in, bool with_jacobian,
                                     std::array<CableStatics, kCableCount>& cables);

// The same statics at a fixed pose, anchors and centre of mass, as the
// affine map it is in the reference cable's force: cable i carries
// (f_h, f_v)_i = offset[i] + gain[i] * (f_h, f_v)_ref (the reference cable:
// offset 0, gain I). One factorisation of Eq. (11) then serves any number of
// reference forces, e.g. a start's search over them. in.reference_force is
// not read.
struct ReferenceForceMap {
  std::array<Eigen::Vector2d, kCableCount> offset;
  std::array<Eigen::Matrix2d, kCableCount> gain;
  std::array<double, kCableCount> span{}, anchor_z{}, attachment_z{};  // as in CableStatics

  // Turning the pose about the world vertical through its origin (yaw, the
  // start's heading search): d span_i / d yaw, and d (f_h, f_v)_i / d yaw at
  // the reference force `f` held fixed (zero for the reference cable). The
  // attachment heights do not change.
  std::array<double, kCableCount> d_span_d_yaw{};
  std::array<Eigen::Vector2d, kCableCount> d_force_d_yaw(const Eigen::Vector2d& f) const;

  // What d_force_d_yaw needs: A^-1, each cable's lever R b and horizontal
  // directions, d w / d yaw, the reference cable.
  Eigen::Matrix<double, 6, 6> inverse;
  std::array<Eigen::Vector3d, kCableCount> lever{}, s_c{}, t{};
  Eigen::Matrix<double, 6, 1> d_weight_d_yaw;
  int reference = 0;
};
StaticsStatus reference_force_map(const Robot& robot, const StaticsInput& in, ReferenceForceMap& map);

}  // namespace cdpr
