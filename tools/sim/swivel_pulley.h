#pragma once
// Where the free cable leaves a swivel pulley (docs/DESIGN.md "Swivel pulley").
//
// The swivel axis is vertical through the fixed anchor point A; the cable
// comes up along that axis and touches the pulley at A. The pulley (radius r)
// lies in the vertical plane through A and the attachment point with its
// centre C = A + r s_c (s_c: horizontal unit vector from A towards the
// attachment), so A is the pulley's point farthest from the attachment. The
// cable wraps over the top and leaves where the circle's tangent has the
// slope of the free cable's end. In the plane coordinates (along s_c, up)
// with origin A, the free cable's direction towards the platform at the
// pulley is (h, -v_end) / |T| for an end tension T = (h, v_end) pointing
// towards the pulley; the departure angle phi (from the +s_c axis, on the
// circle around C) is phi = atan2(h, v_end), the departure point is
// C + r (cos phi, sin phi) and the wrapped arc runs from angle pi down to phi.
// With r = 0 everything reduces to the plain anchor point A.

namespace cdpr::sim {

struct PulleyDeparture {
  double horizontal_m = 0.0;   // r (1 + cos phi): from A towards the attachment
  double height_m = 0.0;       // r sin phi: above A
  double wrapped_arc_m = 0.0;  // r (pi - phi): geometric length of cable on the pulley
};

// `end_h_n` > 0 and `end_v_n` are the horizontal and vertical tension of the
// free cable where it reaches the pulley (T(L0) of sim/cable_shooting.h).
PulleyDeparture pulley_departure(double radius_m, double end_h_n, double end_v_n);

}  // namespace cdpr::sim
