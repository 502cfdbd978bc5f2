// The cable with effects (elastic catenary, density, swivel pulley) against
// the closed-form catenary, an independent quadrature of Hooke's law, and
// central differences of its own Jacobian.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "solver/model/catenary.h"
#include "solver/model/effect_cable.h"

namespace cdpr {
namespace {

// A 150 m cable of the large robot and a taut 10 m cable of the small one.
const EffectCableInput kLargeCable{600.0, 450.0, 130.0, 50.0, 9.81 * 0.0724, 0.0, 0.0};
const EffectCableInput kSmallCable{40.0, 30.0, 9.0, 28.0, 9.81 * 0.0102, 0.0, 0.0};

TEST(EffectCable, WithoutEffectsIsTheCatenaryOfEq1To4) {
  for (const EffectCableInput& in : {kLargeCable, kSmallCable}) {
    EffectCableOutput out;
    ASSERT_TRUE(evaluate_effect_cable(in, false, out));
    const CatenaryOutput catenary =
        evaluate_catenary({in.f_h, in.f_v, in.span, in.anchor_z, in.weight_per_length}, false);
    EXPECT_NEAR(out.payout, catenary.arc_length, 1e-9 * catenary.arc_length);
    EXPECT_NEAR(out.end_height, catenary.end_height, 1e-9 * std::abs(catenary.end_height));
  }
}

// GIVEN an elastic cable, WHEN its shape is integrated from Hooke's law
// (dr/ds = (1 + |T| c) T / |T|, T = (h, v + w s)) over the unstretched length
// the model returns, THEN it spans exactly the horizontal distance and ends
// at the model's height.
TEST(EffectCable, ElasticCatenaryMatchesAQuadratureOfHookesLaw) {
  EffectCableInput in = kLargeCable;
  in.compliance = 1.0 / 1.5e6;
  EffectCableOutput out;
  ASSERT_TRUE(evaluate_effect_cable(in, false, out));
  const int n = 20000;
  const double ds = out.free_unstretched / n;
  double x = 0.0, z = 0.0;
  for (int k = 0; k < n; ++k) {  // midpoint rule, error O(ds^2) ~ 1e-8 m here
    const double s = (k + 0.5) * ds;
    const double v = in.f_v + in.weight_per_length * s;
    const double t = std::hypot(in.f_h, v);
    x += (1.0 + t * in.compliance) * in.f_h / t * ds;
    z += (1.0 + t * in.compliance) * v / t * ds;
  }
  EXPECT_NEAR(x, in.span, 1e-6);
  EXPECT_NEAR(in.anchor_z - z, out.end_height, 1e-6);
  // The stretch is real: the unstretched payout is shorter than the inextensible arc.
  EffectCableOutput rigid;
  ASSERT_TRUE(evaluate_effect_cable(kLargeCable, false, rigid));
  EXPECT_LT(out.payout, rigid.payout - 0.01);
}

// GIVEN a swivel pulley, THEN the free cable leaves it tangentially: the
// departure angle is that of the tension at the free cable's upper end, and
// the payout includes the wrapped arc r (pi - phi).
TEST(EffectCable, PulleyDepartureIsTangentAndPayoutIncludesTheWrap) {
  EffectCableInput in = kLargeCable;
  in.pulley_radius = 0.15;
  EffectCableOutput out;
  ASSERT_TRUE(evaluate_effect_cable(in, false, out));
  const double v_top = in.f_v + in.weight_per_length * out.free_unstretched;
  EXPECT_NEAR(out.departure_angle, std::atan2(in.f_h, v_top), 1e-12);
  EXPECT_NEAR(out.payout - out.free_unstretched, in.pulley_radius * (std::numbers::pi - out.departure_angle), 1e-12);
  // The free cable spans the distance to the departure point, r (1 + cos phi) short of A.
  EffectCableInput free = kLargeCable;
  free.span = in.span - in.pulley_radius * (1.0 + std::cos(out.departure_angle));
  free.anchor_z = in.anchor_z + in.pulley_radius * std::sin(out.departure_angle);
  EffectCableOutput free_out;
  ASSERT_TRUE(evaluate_effect_cable(free, false, free_out));
  EXPECT_NEAR(free_out.payout, out.free_unstretched, 1e-9);
  EXPECT_NEAR(free_out.end_height, out.end_height, 1e-9);
}

void expect_jacobian_matches(const EffectCableInput& base) {
  EffectCableOutput out;
  ASSERT_TRUE(evaluate_effect_cable(base, true, out));
  // Steps large enough against round-off of ~100 m outputs, small against curvature.
  const double steps[kEffectCableParams] = {1e-3, 1e-3, 1e-5, 1e-5, 1e-6, std::max(1e-10, 1e-3 * base.compliance), 1e-6};
  for (int j = 0; j < kEffectCableParams; ++j) {
    EffectCableInput plus = base, minus = base;
    const auto field = [j](EffectCableInput& in) -> double& {
      double* f[kEffectCableParams] = {&in.f_h, &in.f_v, &in.span, &in.anchor_z, &in.weight_per_length,
                                       &in.compliance, &in.pulley_radius};
      return *f[j];
    };
    field(plus) += steps[j];
    field(minus) -= steps[j];
    EffectCableOutput op, om;
    ASSERT_TRUE(evaluate_effect_cable(plus, false, op));
    ASSERT_TRUE(evaluate_effect_cable(minus, false, om));
    const double d_height = (op.end_height - om.end_height) / (2.0 * steps[j]);
    const double d_payout = (op.payout - om.payout) / (2.0 * steps[j]);
    EXPECT_NEAR(out.d_end_height(j), d_height, 1e-6 * std::max(1.0, std::abs(d_height))) << "column " << j;
    EXPECT_NEAR(out.d_payout(j), d_payout, 1e-6 * std::max(1.0, std::abs(d_payout))) << "column " << j;
  }
}

TEST(EffectCable, JacobianMatchesNumericWithoutEffects) {
  expect_jacobian_matches(kLargeCable);
  expect_jacobian_matches(kSmallCable);
}

TEST(EffectCable, JacobianMatchesNumericWithElasticityAndPulley) {
  EffectCableInput large = kLargeCable;
  large.compliance = 1.0 / 1.5e6;
  large.pulley_radius = 0.15;
  expect_jacobian_matches(large);
  EffectCableInput small = kSmallCable;
  small.compliance = 1.0 / 2e5;
  small.pulley_radius = 0.05;
  expect_jacobian_matches(small);
}

TEST(EffectCable, JacobianMatchesNumericForACableSaggingBelowItsAttachment) {
  EffectCableInput sagging = kLargeCable;
  sagging.f_v = -20.0;  // the cable leaves the platform downwards before rising
  sagging.compliance = 1.0 / 1.5e6;
  sagging.pulley_radius = 0.15;
  expect_jacobian_matches(sagging);
}

TEST(EffectCable, RefusesAPushingCable) {
  EffectCableInput pushing = kLargeCable;
  pushing.f_h = -1.0;
  EffectCableOutput out;
  EXPECT_FALSE(evaluate_effect_cable(pushing, true, out));
}

}  // namespace
}  // namespace cdpr
