// The sequential waypoint strategy replayed on the simulator (a few seeds
// here; cdpr-accuracy --strategy runs the full table of docs/calibration.md).
#include <gtest/gtest.h>

#include <cmath>

#include "cdpr-accuracy/replay.h"

namespace cdpr::accuracy {
namespace {

ReplayCase large_case(Strategy strategy) {
  ReplayCase c;
  c.preset = sim::Preset::kLarge;
  c.strategy = strategy;
  c.anchor_perturbation_m = 0.3;
  return c;
}

TEST(SequentialReplay, ReachesTheTargetInAtMostTwoThirdsOfTheSpreadPlansTime) {
  const ReplayCase sequential = large_case(Strategy::kSequential);
  const double target_m = sequential.sequential.target_anchor_sigma_m;
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    // GIVEN the large robot, nominal anchors 0.3 m off; WHEN sequential and the 35-point spread plan run
    const ReplayResult r = replay(sequential, seed);
    const ReplayResult spread = replay(large_case(Strategy::kSpread), seed);
    ASSERT_TRUE(r.ok) << r.message;
    ASSERT_TRUE(spread.ok) << spread.message;
    // THEN sequential stops on its target, and the final fit's sigmas say so
    EXPECT_EQ(r.stop, "target reached");
    EXPECT_LE(r.largest_anchor_sigma_m, 1.1 * target_m);
    EXPECT_LE(r.largest_offset_sigma_m, 1.1 * sequential.sequential.target_offset_sigma_m);
    // AND every anchor is within the target's 3 sigma of the truth
    EXPECT_LE(r.worst_anchor_error_m, 3.0 * target_m);
    // AND it takes fewer waypoints and much less robot time than the spread plan
    EXPECT_LT(r.waypoints, spread.waypoints);
    EXPECT_LT(r.robot_time_s, 2.0 / 3.0 * spread.robot_time_s);
  }
}

TEST(SequentialReplay, JudgesEachRunsSigmasAgainstTheFitsOwnCovariance) {
  // GIVEN a sequential run on the large robot
  const ReplayResult r = replay(large_case(Strategy::kSequential), 2);
  ASSERT_TRUE(r.ok) << r.message;
  // THEN its 16 anchor-axis and offset errors are judged: the same RMS as
  // the error/sigma column, with the spread that honest sigmas with these
  // correlations would give it
  const NormalisedErrors& e = r.normalised;
  ASSERT_EQ(e.count, 16);
  EXPECT_NEAR(e.rms, std::sqrt(r.normalised_sq_sum / r.normalised_count), 1e-12);
  EXPECT_GT(e.mahalanobis, 0.0);
  EXPECT_LT(e.rms_q05, 1.0);
  EXPECT_GT(e.rms_q95, 1.0);
  // AND the anchors' shared frame and offsets correlate the errors: honest
  // sigmas leave the RMS outside 0.7-1.5 far more often than independent
  // errors would (5 %)
  EXPECT_GT(e.p_outside, 0.1);
}

TEST(SequentialReplay, StopsAtMaxCountWhenTheTargetIsOutOfReach) {
  // GIVEN a target no 12 waypoints reach
  ReplayCase c = large_case(Strategy::kSequential);
  c.sequential.target_anchor_sigma_m = 1e-4;
  c.sequential.max_count = 12;
  for (const std::uint64_t seed : {4u, 5u}) {
    SCOPED_TRACE(seed);
    // WHEN replayed
    const ReplayResult r = replay(c, seed);
    // THEN it measures exactly max_count waypoints and says why it stopped
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.stop, "max count");
    EXPECT_EQ(r.waypoints, 12);
    EXPECT_GT(r.largest_anchor_sigma_m, c.sequential.target_anchor_sigma_m);
  }
}

TEST(SequentialReplay, ALooserTargetStopsSooner) {
  // GIVEN the default target and one twice as tight (the default one is
  // often reached by the initial identifiable set alone)
  ReplayCase loose = large_case(Strategy::kSequential);
  ReplayCase tight = loose;
  tight.sequential.target_anchor_sigma_m /= 2.0;
  tight.sequential.target_offset_sigma_m /= 2.0;
  int tight_waypoints = 0, loose_waypoints = 0;
  for (const std::uint64_t seed : {6u, 7u, 8u, 9u}) {
    SCOPED_TRACE(seed);
    // WHEN both are replayed
    const ReplayResult t = replay(tight, seed);
    const ReplayResult l = replay(loose, seed);
    ASSERT_TRUE(t.ok && l.ok);
    // THEN both reach their targets; the greedy paths differ, so the loose
    // one may take a waypoint more on a seed, never several
    EXPECT_EQ(l.stop, "target reached");
    EXPECT_EQ(t.stop, "target reached");
    EXPECT_LE(l.waypoints, t.waypoints + 1);
    tight_waypoints += t.waypoints;
    loose_waypoints += l.waypoints;
  }
  // AND fewer over all seeds: the target drives the stop
  EXPECT_LT(loose_waypoints, tight_waypoints);
}

TEST(SequentialReplay, OnTheSmallRobotWithAnchorsMetresOffTheCandidatesFollowTheEstimate) {
  // GIVEN the small robot with nominal anchors 2 m off, where candidates
  // planned from the nominal anchors sit outside the true workspace
  ReplayCase c;
  c.preset = sim::Preset::kSmall;
  c.strategy = Strategy::kSequential;
  c.anchor_perturbation_m = 2.0;
  ReplayCase fixed = c;
  fixed.replan = false;
  for (const std::uint64_t seed : {1u, 2u}) {
    SCOPED_TRACE(seed);
    // WHEN replayed with the candidates planned again from the estimate, and without
    const ReplayResult r = replay(c, seed);
    const ReplayResult f = replay(fixed, seed);
    ASSERT_TRUE(r.ok && f.ok);
    // THEN re-planned, it reaches the target, within the target's 3 sigma,
    // with fewer waypoints skipped and less robot time than the fixed candidates
    EXPECT_EQ(r.stop, "target reached");
    EXPECT_LE(r.worst_anchor_error_m, 3.0 * c.sequential.target_anchor_sigma_m);
    EXPECT_LT(r.skipped, f.skipped);
    EXPECT_LT(r.robot_time_s, f.robot_time_s);
  }
}

}  // namespace
}  // namespace cdpr::accuracy
