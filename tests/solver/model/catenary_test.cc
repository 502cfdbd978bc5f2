#include "solver/model/catenary.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cdpr {
namespace {

// Eq. (1)-(3) evaluated literally, as an independent reference for the
// product form used in evaluate_catenary.
double literal_height(const CatenaryInput& in, double x) {
  const double gc = in.weight_per_length, fh = in.f_h;
  const double c1 = fh / gc * std::asinh(-in.f_v / fh) - in.span;               // Eq. (2)
  const double c2 = std::cosh(c1 * gc / fh) - gc / fh * in.anchor_z;             // Eq. (3)
  return fh / gc * (std::cosh(gc / fh * (x + c1)) - c2);                          // Eq. (1)
}

// Arc length of Eq. (1) by Simpson quadrature of sqrt(1 + z'^2), Eq. (4)'s integral.
double quadrature_length(const CatenaryInput& in) {
  const int n = 20000;
  const double h = in.span / n;
  auto integrand = [&](double x) {
    const double dz = (literal_height(in, x + 1e-6) - literal_height(in, x - 1e-6)) / 2e-6;
    return std::sqrt(1.0 + dz * dz);
  };
  double sum = integrand(0.0) + integrand(in.span);
  for (int j = 1; j < n; ++j) sum += (j % 2 ? 4.0 : 2.0) * integrand(j * h);
  return sum * h / 3.0;
}

const CatenaryInput kLargeSag{500.0, 150.0, 160.0, 50.0, 9.81 * 0.0724};
const CatenaryInput kPushDown{500.0, -40.0, 160.0, 50.0, 9.81 * 0.0724};  // cable pulls the platform down
const CatenaryInput kTautSmall{20.0, 15.0, 6.0, 28.5, 9.81 * 0.0102};

TEST(Catenary, MatchesLiteralEquationsOneToFour) {
  for (const CatenaryInput& in : {kLargeSag, kPushDown, kTautSmall}) {
    // GIVEN a cable state; WHEN evaluated
    const CatenaryOutput out = evaluate_catenary(in, false);
    // THEN the end height is Eq. (1) at x = L and the length its arc integral.
    EXPECT_NEAR(out.end_height, literal_height(in, in.span), 1e-9 * in.span);
    EXPECT_NEAR(out.arc_length, quadrature_length(in), 1e-7 * in.span);
    EXPECT_NEAR(literal_height(in, 0.0), in.anchor_z, 1e-9);
  }
}

TEST(Catenary, SlopeAtAttachmentIsForceRatio) {
  // GIVEN the boundary condition z'(L) = -f_v / f_h of Eq. (2)
  const CatenaryInput in = kLargeSag;
  const double slope = (literal_height(in, in.span + 1e-5) - literal_height(in, in.span - 1e-5)) / 2e-5;
  EXPECT_NEAR(slope, -in.f_v / in.f_h, 1e-6);
}

TEST(Catenary, ApproachesStraightLineWhenWeightless) {
  // GIVEN a nearly weightless cable whose end force points along the chord
  CatenaryInput in{1000.0, 500.0, 30.0, 10.0, 1e-9};
  const CatenaryOutput out = evaluate_catenary(in, false);
  // THEN it ends on the straight line of slope -f_v/f_h with the chord's length
  EXPECT_NEAR(out.end_height, 10.0 - 15.0, 1e-6);
  EXPECT_NEAR(out.arc_length, std::hypot(30.0, 15.0), 1e-6);
}

TEST(Catenary, JacobianMatchesCentralDifferences) {
  for (const CatenaryInput& in : {kLargeSag, kPushDown, kTautSmall}) {
    const CatenaryOutput out = evaluate_catenary(in, true);
    for (int j = 0; j < 4; ++j) {
      const double h = j < 2 ? 1e-3 : 1e-5;
      CatenaryInput plus = in, minus = in;
      double* fields_p[4] = {&plus.f_h, &plus.f_v, &plus.span, &plus.anchor_z};
      double* fields_m[4] = {&minus.f_h, &minus.f_v, &minus.span, &minus.anchor_z};
      *fields_p[j] += h;
      *fields_m[j] -= h;
      const CatenaryOutput op = evaluate_catenary(plus, false), om = evaluate_catenary(minus, false);
      EXPECT_NEAR(out.d_end_height(j), (op.end_height - om.end_height) / (2 * h), 1e-6) << "column " << j;
      EXPECT_NEAR(out.d_arc_length(j), (op.arc_length - om.arc_length) / (2 * h), 1e-6) << "column " << j;
    }
  }
}

}  // namespace
}  // namespace cdpr
