// End-to-end accuracy of the calibration on data from the independent
// simulator (a few seeds here; cdpr-accuracy runs the full 50-seed figures).
#include <gtest/gtest.h>

#include "cdpr-accuracy/accuracy.h"
#include "cdpr-accuracy/model_check.h"

namespace cdpr::accuracy {
namespace {

TEST(ModelCheck, CatenaryMatchesSimulatedEquilibriumLikeTableI) {
  for (sim::Preset preset : {sim::Preset::kLarge, sim::Preset::kSmall}) {
    // GIVEN the simulator's true equilibria; WHEN the fitting model predicts them
    const ModelCheck c = model_check(preset, 10, 3);
    ASSERT_TRUE(c.error.empty()) << c.error;
    // THEN lengths agree to better than 0.01 % and forces to better than 1 %
    EXPECT_LT(c.max_length_error_pct, 0.01);
    EXPECT_LT(c.max_force_error_pct, 1.0);
  }
}

TEST(Accuracy, NoiselessDataIsRecoveredExactlyFromTenMetrePerturbation) {
  // GIVEN 35 poses without sensor noise and anchors 10 m off
  Case c;
  c.poses = 35;
  c.noise_scale = 0.0;
  const RunResult run = run_case(c, 11);
  // THEN the fit is exact: no bias in the model or the start
  // (noise is what limits the real figures; see cdpr-accuracy)
  ASSERT_TRUE(run.ok) << run.message;
  EXPECT_LT(run.anchor_error_m, 1e-4);
  EXPECT_LT(run.offset_error_m, 1e-4);
  // AND the fit's sigmas (the catenary model's Cramer-Rao bound here) are of the size the
  // straight-cable bound of the same poses predicts: sag moves the cable directions a little
  // and adds the force per pose as an unknown, it does not change what the encoders can tell
  EXPECT_GT(run.straight_bound_m, 0.01);
  EXPECT_GT(run.reported_sigma_m, 0.5 * run.straight_bound_m);
  EXPECT_LT(run.reported_sigma_m, 2.0 * run.straight_bound_m);
}

TEST(Accuracy, TheIterationLimitIsTheFitsOwn) {
  // GIVEN a case whose fit needs several iterations, allowed only 2
  Case c;
  c.poses = 9;
  c.max_iterations = 2;
  const RunResult run = run_case(c, 3);
  // THEN the fit stops there, far from the truth
  EXPECT_LE(run.iterations, 2);
  EXPECT_GT(run.anchor_error_m, 0.3);
}

TEST(Accuracy, LargeRobotWithWideWaypointsBeatsPaperAndRigidModel) {
  // GIVEN the large robot, 35 waypoints spread over the planner's wide box, noise as in the paper
  Case c;
  c.workspace_min = Eigen::Vector3d(50, 45, 5);
  c.workspace_max = Eigen::Vector3d(190, 175, 35);
  std::vector<RunResult> catenary, rigid;
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    c.model = CableModelKind::kCatenary;
    catenary.push_back(run_case(c, seed));
    c.model = CableModelKind::kRigid;
    rigid.push_back(run_case(c, seed));
  }
  const Summary cat = summarise(catenary), rig = summarise(rigid);
  // THEN the catenary fit meets the 0.10 m target (the paper reports 0.19 m), is far better than
  // the rigid model, and its sigmas are honest
  EXPECT_LE(cat.anchor.mean, 0.10);
  EXPECT_LE(cat.offset.mean, 0.10);
  EXPECT_EQ(cat.failures, 0);
  EXPECT_LT(cat.anchor.mean * 5.0, rig.anchor.mean);
  EXPECT_GT(cat.normalised_rms, 0.4);
  EXPECT_LT(cat.normalised_rms, 2.0);
}

}  // namespace
}  // namespace cdpr::accuracy
