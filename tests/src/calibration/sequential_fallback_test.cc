// The sequential strategy's fallback as the daemon meets it: a re-solve that
// fails does not end the run; the state machine drives the next unused
// candidate in spread order and the run log says why.

#include "src/calibration/calibration_state_machine.h"

#include <algorithm>
#include <vector>

#include <gtest/gtest.h>

#include "calibration_rig.h"
#include "../../text_contains.h"

namespace cdpr::calibration {
namespace {

TEST(SequentialFallback, FailedReSolvesDriveTheSpreadOrderThroughTheStateMachine) {
  // GIVEN the sequential strategy, at most 10 samples, and re-solves that
  // all fail
  CalibratorOptions options = test::rig_options();
  options.planner.grid_xy = 4;
  options.strategy = WaypointStrategy::kSequential;
  options.sequential.max_count = 10;
  int resolves = 0;
  options.sequential.resolve = [&resolves](const Robot&, const std::vector<Sample>&, const CalibrationOptions&) {
    ++resolves;
    CalibrationResult failed;
    failed.message = "no start converged";
    return failed;
  };
  test::CalibrationRig rig(options);
  rig.use_model_tension();
  // WHEN a run goes to the end
  ASSERT_TRUE(rig.machine->request_start(rig.clock.now_us()));
  ASSERT_TRUE(rig.run_to_end());
  // THEN it still samples up to max_count and commits the final solve
  EXPECT_EQ(rig.status().state, CalibrationState::kDone) << rig.status().reason;
  EXPECT_EQ(rig.status().samples, 10);
  EXPECT_EQ(rig.status().stop_reason, "max count");
  // AND after the initial set every waypoint is the next unused candidate in
  // spread order, each logged with the reason
  const std::vector<Waypoint>& candidates = rig.machine->plan().waypoints;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Waypoint& w : candidates) centre += w.rest.world_T_platform.position_world / candidates.size();
  const std::vector<int> spread = spread_waypoints(candidates, centre, static_cast<int>(candidates.size()));
  std::vector<int> sampled;
  for (const Sample& sample : rig.machine->samples()) {
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      if ((sample.position_world - candidates[k].rest.world_T_platform.position_world).norm() < 1e-9) {
        sampled.push_back(static_cast<int>(k));
      }
    }
  }
  ASSERT_EQ(sampled.size(), 10u);
  const auto& logged = rig.machine->run_log().waypoints;
  ASSERT_EQ(logged.size(), 10u);
  int fallbacks = 0;
  for (std::size_t j = 0; j < logged.size(); ++j) {
    if (!::cdpr::test::contains(logged[j].why, "failed: next waypoint in spread order")) continue;
    ++fallbacks;
    // The waypoint after a logged fallback is the first spread candidate not sampled before it.
    ASSERT_LT(j + 1, sampled.size());
    const std::vector<int> before(sampled.begin(), sampled.begin() + static_cast<long>(j) + 1);
    const auto next = std::find_if(spread.begin(), spread.end(), [&](int k) {
      return std::find(before.begin(), before.end(), k) == before.end();
    });
    ASSERT_NE(next, spread.end());
    EXPECT_EQ(sampled[j + 1], *next) << "waypoint " << j + 2;
  }
  // (the last sample ends the run by max_count: no next waypoint to log)
  EXPECT_GE(fallbacks, 2);
  EXPECT_EQ(fallbacks + 1, resolves);
}

}  // namespace
}  // namespace cdpr::calibration
