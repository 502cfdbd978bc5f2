#include "solver/operation/health_watch.h"

#include <cmath>

#include "solver/operation/refit.h"

#include <gtest/gtest.h>

#include "simulated_rests.h"

namespace cdpr {
namespace {

// Feeds every rest; returns the rest at which the watch fired, or -1.
int watch_all(HealthWatch& watch, const std::vector<Sample>& rests) {
  int fired = -1;
  for (const Sample& rest : rests) {
    const RestCheck check = watch.add_rest(rest);
    EXPECT_TRUE(check.checked) << "rest " << check.rest << ": " << check.why;
    if (check.fired) fired = check.rest;
  }
  return fired;
}

// A 2 cm slip of `cable`'s encoder from rest 10.
sim::InjectedFault slip_from_rest_10(int cable) {
  sim::InjectedFault slip;
  slip.kind = sim::FaultKind::kEncoderSlip;
  slip.cable = cable;
  slip.size = 0.02;
  slip.from_rest = 10;
  return slip;
}

TEST(HealthWatch, CleanRestsRaiseNoAlarm) {
  // GIVEN a robot whose calibration is right
  const test::WatchedRests r = test::watched_rests(sim::Preset::kLarge, 40, 11);
  HealthWatch watch(r.sequence.nominal, r.calibration);
  // WHEN it rests 40 times
  const int fired = watch_all(watch, r.sequence.rests);
  // THEN the watch stays quiet
  EXPECT_EQ(fired, -1);
  EXPECT_FALSE(watch.stale());
  // AND its threshold is the designed one: one false alarm per 1000 clean
  // rests over 50 one-sided CUSUMs by Siegmund's approximation at delta 1.5
  EXPECT_NEAR(watch.threshold(), std::log(50.0 * 1000.0 * 1.5 * 1.5 / 2.0) - 1.166 * 1.5, 1e-9);
}

TEST(HealthWatch, AnEncoderSlipIsFlaggedSoonAndNamesItsCable) {
  // GIVEN the encoder of cable 2 slips by 2 cm at rest 10
  const sim::InjectedFault slip = slip_from_rest_10(2);
  const test::WatchedRests r = test::watched_rests(sim::Preset::kLarge, 30, 12, slip);
  HealthWatch watch(r.sequence.nominal, r.calibration);
  // WHEN the watch sees the rests
  const int fired = watch_all(watch, r.sequence.rests);
  // THEN it fires within 10 rests of the slip, naming that encoder's offset and its size
  ASSERT_TRUE(watch.stale());
  EXPECT_GE(fired, 10);
  EXPECT_LT(fired, 20);
  const StaleFinding& f = *watch.finding();
  EXPECT_EQ(f.term.term, FaultTerm::kEncoderOffset) << fault_term_name(f.term.term, f.term.cable);
  EXPECT_EQ(f.term.cable, 2);
  EXPECT_NEAR(f.term.value(0), 0.02, 4.0 * f.term.sigma(0));
  EXPECT_TRUE(f.calibration_fault());

  // AND the re-fit it offers from the rests since brings the offset back to the truth
  std::string why;
  const auto refit = refit_from_rests(r.sequence.nominal, r.calibration, watch.rests_since_onset(),
                                      refit_request_for(f), {}, &why);
  ASSERT_TRUE(refit) << why;
  const double truth = r.sequence.true_robot.encoder_offset_m[2] + 0.02;
  EXPECT_NEAR(refit->winches[2].offset_m, truth, 4.0 * refit->winches[2].offset_sigma_m);
  EXPECT_GT(std::abs(r.calibration.winches[2].offset_m - truth), 0.015);
}

TEST(HealthWatch, APayloadChangeIsNamedAsTheLoadNotACalibrationFault) {
  sim::InjectedFault payload;
  payload.kind = sim::FaultKind::kPayloadChange;
  payload.size = 5.0;  // kg, on a 34 kg platform
  payload.com_shift_platform = Eigen::Vector3d(0.03, 0.0, 0.0);
  payload.from_rest = 5;
  const test::WatchedRests r = test::watched_rests(sim::Preset::kLarge, 25, 13, payload);
  HealthWatch watch(r.sequence.nominal, r.calibration);
  watch_all(watch, r.sequence.rests);
  ASSERT_TRUE(watch.stale());
  EXPECT_EQ(watch.finding()->term.term, FaultTerm::kLoad);
  EXPECT_FALSE(watch.finding()->calibration_fault());
}

// A calibration whose offset of cable 1 is off by 1.8 cm, within its stated
// 2 cm sigma (the rest as good as the others'): what a calibration's own
// error does to the statistics.
test::WatchedRests rests_with_an_honest_offset_error(sim::InjectedFault fault = {}) {
  test::WatchedRests r = test::watched_rests(sim::Preset::kLarge, 40, 14, fault);
  r.calibration.winches[1].offset_m = r.sequence.true_robot.encoder_offset_m[1] - 0.018;
  r.calibration.winches[1].offset_sigma_m = 0.02;
  return r;
}

TEST(HealthWatch, ACalibrationsOwnErrorWithinItsSigmaIsNoChange) {
  // GIVEN a calibration off by 1.8 cm in one offset, as its sigma allows
  const test::WatchedRests r = rests_with_an_honest_offset_error();
  // WHEN the watch tracks the calibration's error over 40 clean rests
  HealthWatchOptions tracking;
  tracking.calibration_error = CalibrationErrorHandling::kTracked;
  HealthWatch tracked(r.sequence.nominal, r.calibration, tracking);
  // THEN it stays quiet: the error is the same at every rest, not a change
  EXPECT_EQ(watch_all(tracked, r.sequence.rests), -1);
  // WHILE the scores taken as they come see a standing 1.8 cm shift of a
  // 2 cm-designed test and call it a change
  HealthWatch naive(r.sequence.nominal, r.calibration);
  EXPECT_GE(watch_all(naive, r.sequence.rests), 0);
  // AND held after a reference window of 10 rests, the same
  tracking.calibration_error_rests = 10;
  HealthWatch windowed(r.sequence.nominal, r.calibration, tracking);
  EXPECT_EQ(watch_all(windowed, r.sequence.rests), -1);
}

TEST(HealthWatch, ASlipOnTopOfTheCalibrationsOwnErrorIsStillFlagged) {
  // GIVEN the same calibration and a 2 cm slip of cable 3 at rest 10
  const sim::InjectedFault slip = slip_from_rest_10(3);
  const test::WatchedRests r = rests_with_an_honest_offset_error(slip);
  HealthWatchOptions tracking;
  tracking.calibration_error = CalibrationErrorHandling::kTracked;
  tracking.calibration_error_rests = 10;
  HealthWatch watch(r.sequence.nominal, r.calibration, tracking);
  // WHEN the watch sees the rests
  const int fired = watch_all(watch, r.sequence.rests);
  // THEN it fires within 10 rests of the slip and names cable 3, not cable 1
  ASSERT_TRUE(watch.stale());
  EXPECT_GE(fired, 10);
  EXPECT_LT(fired, 20);
  EXPECT_EQ(fault_term_name(watch.finding()->term.term, watch.finding()->term.cable), "offset[3]");
}

// What the watch (default options) named over all of `r`'s rests.
struct Named {
  std::string term;  // empty when it did not go stale
  std::optional<AnchorOrOffset> anchor_or_offset;
};
Named watched_finding(const test::WatchedRests& r) {
  HealthWatch watch(r.sequence.nominal, r.calibration);
  watch_all(watch, r.sequence.rests);
  if (!watch.stale()) return {};
  const StaleFinding& f = *watch.finding();
  return {fault_term_name(f.term.term, f.term.cable), f.anchor_or_offset};
}

TEST(HealthWatch, ASlipIsNotNamedAnAnchorMoveTheRestsCannotResolve) {
  // GIVEN the encoder of cable 2 slips by 2 cm at rest 10
  const sim::InjectedFault slip = slip_from_rest_10(2);
  // WHEN the watch sees the rests
  const Named named = watched_finding(test::watched_rests(sim::Preset::kLarge, 30, 12, slip));
  // THEN the finding weighs anchor[2] against offset[2] and names no anchor
  ASSERT_TRUE(named.anchor_or_offset.has_value());
  const AnchorOrOffset* a = &*named.anchor_or_offset;
  EXPECT_EQ(a->cable, 2);
  EXPECT_NEAR(a->margin, 11.34, 0.01);  // chi-square, 3 degrees of freedom, 1 % above
  EXPECT_FALSE(a->anchor_named()) << "2 ln LR " << a->log_likelihood_ratio;
  EXPECT_EQ(named.term, "offset[2]");
  // AND says how far the rests resolve a move beyond an offset change
  EXPECT_GT(a->best_sigma_m, 0.0);
  EXPECT_TRUE(std::isfinite(a->best_sigma_m));
}

TEST(HealthWatch, TheAnchorsMarginIsTheChiSquareQuantileOfItsMisnamingRate) {
  // GIVEN a slip's finding (2 ln LR of anchor over offset: at most chi-square, 3 dof)
  const test::WatchedRests r = test::watched_rests(sim::Preset::kLarge, 30, 12, slip_from_rest_10(2));
  for (const auto& [rate, quantile] : {std::pair{0.01, 11.345}, std::pair{0.05, 7.815}, std::pair{0.001, 16.266}}) {
    HealthWatchOptions options;
    options.anchor_misnaming_rate = rate;
    HealthWatch watch(r.sequence.nominal, r.calibration, options);
    watch_all(watch, r.sequence.rests);
    ASSERT_TRUE(watch.stale() && watch.finding()->anchor_or_offset);
    EXPECT_NEAR(watch.finding()->anchor_or_offset->margin, quantile, 2e-3) << "rate " << rate;
  }
}

TEST(HealthWatch, AnAnchorMoveTheRestsResolveIsNamed) {
  // GIVEN anchor 1 of the large robot moved 15 cm at rest 5, horizontally
  // across its cable: what an offset change cannot mimic over the rests'
  // spread of cable directions
  const test::WatchedRests before = test::watched_rests(sim::Preset::kLarge, 1, 15);
  const Eigen::Vector3d along =
      before.sequence.true_robot.robot.winches[1].anchor_world - before.sequence.rests[0].position_world;
  sim::InjectedFault moved;
  moved.kind = sim::FaultKind::kAnchorMoved;
  moved.cable = 1;
  moved.size = 0.15;
  moved.direction_world = along.cross(Eigen::Vector3d::UnitZ());
  moved.from_rest = 5;
  // WHEN the watch sees the rests
  const Named named = watched_finding(test::watched_rests(sim::Preset::kLarge, 40, 15, moved));
  // THEN the anchor wins the likelihood-ratio test by the margin, and is named
  ASSERT_TRUE(named.anchor_or_offset.has_value());
  EXPECT_TRUE(named.anchor_or_offset->separable()) << "fitted move " << named.anchor_or_offset->fitted_move_sigmas;
  EXPECT_TRUE(named.anchor_or_offset->anchor_named()) << "2 ln LR " << named.anchor_or_offset->log_likelihood_ratio;
  EXPECT_EQ(named.term, "anchor[1]");
}

TEST(HealthWatch, TermNamesAreDiagnosesCatalogue) {
  EXPECT_EQ(fault_term_name(FaultTerm::kEncoderOffset, 1), "offset[1]");
  EXPECT_EQ(fault_term_name(FaultTerm::kAnchor, 3), "anchor[3]");
  EXPECT_EQ(fault_term_name(FaultTerm::kCableElongation, 0), "encoder_scale[0]");
  EXPECT_EQ(fault_term_name(FaultTerm::kLoad, -1), "load");
}

}  // namespace
}  // namespace cdpr
