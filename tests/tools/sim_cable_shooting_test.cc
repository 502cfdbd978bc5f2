// The integrator of the simulator's cable against closed forms: the paper's
// catenary Eq. (1)-(4) for an inextensible cable, Irvine's elastic catenary,
// and Hooke's law for a vertical hanging cable.
#include "sim/cable_shooting.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace cdpr::sim {
namespace {

constexpr double kInextensible = std::numeric_limits<double>::infinity();
constexpr double kLargeWeight = 9.81 * 0.0724;  // N/m, paper's large robot
constexpr double kSmallWeight = 9.81 * 0.0102;

// Paper Eq. (1)-(4), literally: frame x from the anchor (x = 0, height
// anchor_z) towards the attachment (x = span), forces (f_h, f_v) on the platform.
struct PaperCatenary {
  double end_height, arc_length;
};
PaperCatenary paper_catenary(double f_h, double f_v, double span, double anchor_z, double g_c) {
  const double c1 = f_h / g_c * std::asinh(-f_v / f_h) - span;                 // Eq. (2)
  const double c2 = std::cosh(c1 * g_c / f_h) - g_c / f_h * anchor_z;           // Eq. (3)
  auto z = [&](double x) { return f_h / g_c * (std::cosh(g_c / f_h * (x + c1)) - c2); };  // Eq. (1)
  const double length = f_h / g_c * (std::sinh(g_c / f_h * (span + c1)) - std::sinh(g_c / f_h * c1));  // Eq. (4)
  return {z(span), length};
}

struct ShotCase {
  double h, v, length, weight;
};
const ShotCase kCases[] = {
    {700.0, 90.0, 170.0, kLargeWeight},   // large robot, strong sag
    {480.0, -30.0, 140.0, kLargeWeight},  // cable pulls the platform down
    {12.0, 11.0, 20.0, kSmallWeight},     // small robot, nearly straight
};

TEST(SimCableShooting, InextensibleMatchesPaperCatenary) {
  for (const ShotCase& c : kCases) {
    // GIVEN an inextensible cable shot from the attachment with force (h, v)
    const CableShot shot = shoot_cable({c.weight, kInextensible}, c.h, c.v, c.length, 2000);
    // WHEN the paper's catenary is put through the same anchor (the shot's end)
    const double span = shot.end.x();
    const double anchor_z = shot.end.y();  // attachment at height 0
    const PaperCatenary paper = paper_catenary(c.h, c.v, span, anchor_z, c.weight);
    // THEN it reaches the attachment's height and has the shot's length
    EXPECT_NEAR(paper.end_height, 0.0, 1e-6 * c.length);
    EXPECT_NEAR(paper.arc_length, c.length, 1e-6 * c.length);
    EXPECT_DOUBLE_EQ(shot.stretched_length_m, c.length);
  }
}

// Irvine's elastic catenary, the shot's ODE integrated in closed form.
Eigen::Vector2d elastic_catenary_end(double h, double v, double length, double w, double ea) {
  const double top = v + w * length;
  return {h * length / ea + h / w * (std::asinh(top / h) - std::asinh(v / h)),
          (v * length + 0.5 * w * length * length) / ea + h / w * (std::hypot(1.0, top / h) - std::hypot(1.0, v / h))};
}

TEST(SimCableShooting, ElasticMatchesIrvineCatenary) {
  for (const ShotCase& c : kCases) {
    for (const double ea : {2.0e5, 5.0e6}) {
      // GIVEN an elastic cable; WHEN shot
      const CableShot shot = shoot_cable({c.weight, ea}, c.h, c.v, c.length, 2000);
      // THEN its end is the closed-form elastic catenary's
      const Eigen::Vector2d expected = elastic_catenary_end(c.h, c.v, c.length, c.weight, ea);
      EXPECT_NEAR((shot.end - expected).norm(), 0.0, 1e-9 * c.length);
    }
  }
}

TEST(SimCableShooting, VerticalHangingCableStretchesByHookesLaw) {
  // GIVEN a cable hanging straight down from its anchor, carrying 300 N at its end
  const double length = 50.0, load = 300.0, ea = 1.0e5;
  const CableShot shot = shoot_cable({kLargeWeight, ea}, 1e-9, load, length, 500);
  // THEN it stretches by the integral of (load + w s) / EA
  const double stretch = (load * length + 0.5 * kLargeWeight * length * length) / ea;
  EXPECT_NEAR(shot.end.y(), length + stretch, 1e-9 * length);
  EXPECT_NEAR(shot.stretched_length_m, length + stretch, 1e-9 * length);
  EXPECT_NEAR(shot.end.x(), 0.0, 1e-6);
}

TEST(SimCableShooting, DiscretisationConvergesBelowOneInTenMillion) {
  const ShotCase c = kCases[0];
  const CableProperties props{c.weight, 1.0e6};
  // GIVEN the same cable at increasing segment counts
  const CableShot reference = shoot_cable(props, c.h, c.v, c.length, 16000);
  double previous_error = std::numeric_limits<double>::infinity();
  for (const int segments : {1, 2, 4, 8}) {
    const double error = (shoot_cable(props, c.h, c.v, c.length, segments).end - reference.end).norm() / c.length;
    // THEN the error falls with the segment count (Simpson: fourth order)
    EXPECT_LT(error, previous_error);
    previous_error = error;
  }
  // AND at the default count it is far below 1e-7 of the length
  EXPECT_LT((shoot_cable(props, c.h, c.v, c.length, 2000).end - reference.end).norm() / c.length, 1e-7);
}

TEST(SimCableShooting, DerivativesMatchCentralDifferences) {
  for (const ShotCase& c : kCases) {
    const CableProperties props{c.weight, 3.0e5};
    const CableShot shot = shoot_cable(props, c.h, c.v, c.length, 400);
    const double x[3] = {c.h, c.v, c.length};
    for (int j = 0; j < 3; ++j) {
      // GIVEN a small change of h, v or L0
      double plus[3] = {x[0], x[1], x[2]}, minus[3] = {x[0], x[1], x[2]};
      const double step = 1e-5 * std::abs(x[j]);
      plus[j] += step;
      minus[j] -= step;
      // WHEN the cable is shot again at 16x the segments (the L0 column is
      // the ODE's derivative, exact only in the continuous limit)
      const Eigen::Vector2d numeric =
          (shoot_cable(props, plus[0], plus[1], plus[2], 6400).end -
           shoot_cable(props, minus[0], minus[1], minus[2], 6400).end) / (2.0 * step);
      // THEN the shot's derivative column agrees
      EXPECT_NEAR((shot.d_end.col(j) - numeric).norm(), 0.0, 1e-6 * numeric.norm()) << "column " << j;
    }
  }
}

}  // namespace
}  // namespace cdpr::sim
