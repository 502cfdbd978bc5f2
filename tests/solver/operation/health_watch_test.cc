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
  sim::InjectedFault slip;
  slip.kind = sim::FaultKind::kEncoderSlip;
  slip.cable = 2;
  slip.size = 0.02;
  slip.from_rest = 10;
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

TEST(HealthWatch, TermNamesAreDiagnosesCatalogue) {
  EXPECT_EQ(fault_term_name(FaultTerm::kEncoderOffset, 1), "offset[1]");
  EXPECT_EQ(fault_term_name(FaultTerm::kAnchor, 3), "anchor[3]");
  EXPECT_EQ(fault_term_name(FaultTerm::kCableElongation, 0), "encoder_scale[0]");
  EXPECT_EQ(fault_term_name(FaultTerm::kLoad, -1), "load");
}

}  // namespace
}  // namespace cdpr
