// The state machine with the real solver (solver/calibration/calibrate.h) on data that
// the catenary model explains exactly: the platform rests at each planned
// pose, the encoders read the planned payouts and the load cell the modelled
// reference tension. The fit must then give back the geometry the data came
// from.

#include <gtest/gtest.h>

#include "calibration_rig.h"

namespace cdpr::calibration {
namespace {

TEST(CalibrationEndToEnd, RealSolverRecoversTheGeometryOfConsistentData) {
  // GIVEN the rig with model-consistent sensors, 35 waypoints (as on the large robot) and the real solver
  CalibratorOptions options = test::rig_options();
  options.planner.waypoint_count = 35;
  options.planner.grid_xy = 6;
  options.planner.grid_z = 3;
  test::CalibrationRig rig(options);
  rig.use_model_tension();
  const SolveFunction real_solver = make_solver_function(CalibrationOptions{});
  rig.solve = real_solver;
  // WHEN a calibration runs to the end
  rig.button.press();
  ASSERT_TRUE(rig.run_to_end());
  // THEN it is committed, and the anchors and offsets are those the data came from
  ASSERT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
  const auto current = rig.store.load_current();
  ASSERT_TRUE(current && current->has_value());
  const Calibration& calibration = (*current)->calibration;
  ASSERT_EQ(calibration.winches.size(), 4u);
  for (int i = 0; i < kCableCount; ++i) {
    EXPECT_LT((calibration.winches[i].anchor_world - rig.robot.winches[i].anchor_world).norm(), 0.01) << "cable " << i;
    EXPECT_NEAR(calibration.winches[i].offset_m, 2.0, 0.01) << "cable " << i;
  }
  EXPECT_EQ(calibration.samples, 35);
}

}  // namespace
}  // namespace cdpr::calibration
