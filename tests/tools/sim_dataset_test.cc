// Simulated data sets: the paper's ranges, reproducibility from the seed,
// each hidden effect moving the sensors the documented way (sim/sensors.h),
// and files that the formats read back.
#include "sim/dataset.h"

#include <algorithm>
#include <functional>

#include <gtest/gtest.h>

#include "solver/calibration/pose_design.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::sim {
namespace {

DatasetConfig noiseless(Preset preset, int poses, std::uint64_t seed = 3) {
  DatasetConfig c;
  c.preset = preset;
  c.pose_count = poses;
  c.seed = seed;
  c.noise_scale = 0.0;
  c.segments = 400;
  return c;
}

SimulatedDataset simulate(const DatasetConfig& config) {
  auto data = simulate_dataset(config);
  EXPECT_TRUE(data) << (data ? "" : data.error());
  return data ? std::move(*data) : SimulatedDataset{};
}

struct Range {
  double min = 1e300, max = -1e300;
  void add(double v) { min = std::min(min, v), max = std::max(max, v); }
};

TEST(SimDataset, PresetsSpanThePapersLengthAndForceRanges) {
  // Paper Table I: large l in [134.7, 200.7] m, f in [489.1, 954.3] N;
  // small l in [10.8, 25.9] m, f in [12.4, 26.2] N. Our small platform hangs
  // its reference cable more steeply, so its forces start lower.
  struct Expected {
    Preset preset;
    double l_low, l_high, f_low, f_high;
  };
  for (const Expected& e : {Expected{Preset::kLarge, 125.0, 210.0, 400.0, 1100.0},
                            Expected{Preset::kSmall, 10.0, 28.0, 5.0, 28.0}}) {
    // GIVEN a 35-pose data set; WHEN simulated
    const SimulatedDataset data = simulate(noiseless(e.preset, 35));
    ASSERT_EQ(data.samples.size(), 35u);
    Range length, force;
    for (const Equilibrium& s : data.states) {
      for (const CableEquilibrium& c : s.cables) length.add(c.arc_length_m);
      force.add(s.cables[0].tension_n);
    }
    // THEN lengths and reference forces stay within, and spread over most of, the paper's ranges
    EXPECT_GE(length.min, e.l_low);
    EXPECT_LE(length.max, e.l_high);
    EXPECT_GE(force.min, e.f_low);
    EXPECT_LE(force.max, e.f_high);
    EXPECT_GT(length.max - length.min, 0.5 * (e.l_high - e.l_low));
    EXPECT_GT(force.max - force.min, 0.3 * (e.f_high - e.f_low));
  }
}

TEST(SimDataset, SameSeedSameDataOtherSeedOtherData) {
  DatasetConfig config;  // with noise
  config.pose_count = 5;
  config.anchor_perturbation_m = 10.0;
  // GIVEN two runs with one seed and one with another
  const SimulatedDataset a = simulate(config);
  const SimulatedDataset b = simulate(config);
  config.seed += 1;
  const SimulatedDataset c = simulate(config);
  // THEN the first two write identical files and the third differs
  EXPECT_EQ(formats::format_samples_csv(a.samples), formats::format_samples_csv(b.samples));
  EXPECT_EQ(formats::format_robot_toml(a.nominal), formats::format_robot_toml(b.nominal));
  EXPECT_EQ(formats::format_truth_toml(a.truth), formats::format_truth_toml(b.truth));
  EXPECT_NE(formats::format_samples_csv(a.samples), formats::format_samples_csv(c.samples));
  EXPECT_NE(formats::format_robot_toml(a.nominal), formats::format_robot_toml(c.nominal));
  EXPECT_NE(a.truth.winches[0].offset_m, c.truth.winches[0].offset_m);
}

TEST(SimDataset, FilesReadBackAndNominalAnchorsArePerturbedByTheNorm) {
  DatasetConfig config = noiseless(Preset::kSmall, 4);
  config.anchor_perturbation_m = 0.7;
  config.effects.force_bias_n = 0.5;
  // GIVEN a data set; WHEN its files are formatted and parsed again
  const SimulatedDataset data = simulate(config);
  const auto robot = formats::parse_robot_toml(formats::format_robot_toml(data.nominal), "robot.toml");
  ASSERT_TRUE(robot) << robot.error().message();
  const auto samples = formats::parse_samples_csv(formats::format_samples_csv(data.samples), "samples.csv", 4);
  ASSERT_TRUE(samples) << samples.error().message();
  const auto truth = formats::parse_truth_toml(formats::format_truth_toml(data.truth), "truth.toml");
  ASSERT_TRUE(truth) << truth.error().message();
  // THEN nominal anchors sit the perturbation's norm from the true ones
  for (int i = 0; i < kCableCount; ++i) {
    EXPECT_NEAR((robot->winches[i].anchor_world - truth->winches[i].anchor_world).norm(), 0.7, 1e-9);
  }
  EXPECT_EQ(samples->size(), 4u);
  EXPECT_EQ(truth->effects.at("force_bias"), std::vector<double>{0.5});
}

// Sensor readings with one effect against those without (same seed, no noise).
struct Shift {
  std::vector<std::array<double, kCableCount>> encoder;  // with - without, per sample
  std::vector<double> force;
  SimulatedDataset with, without;
};
Shift shift_of(const std::function<void(HiddenEffects&)>& set_effect, Preset preset = Preset::kLarge) {
  DatasetConfig config = noiseless(preset, 6);
  Shift s;
  s.without = simulate(config);
  set_effect(config.effects);
  s.with = simulate(config);
  EXPECT_EQ(s.with.samples.size(), s.without.samples.size());
  for (std::size_t k = 0; k < s.with.samples.size(); ++k) {
    std::array<double, kCableCount> d{};
    for (int i = 0; i < kCableCount; ++i) d[i] = s.with.samples[k].encoder_m[i] - s.without.samples[k].encoder_m[i];
    s.encoder.push_back(d);
    s.force.push_back(s.with.samples[k].force_n - s.without.samples[k].force_n);
  }
  return s;
}

TEST(SimDataset, EncoderScaleMultipliesThePayout) {
  // GIVEN encoder scales s_i; THEN enc_i grows by s_i * payout_i at the same poses
  const Shift s = shift_of([](HiddenEffects& e) { e.encoder_scale = {0.001, -0.002, 0.0, 0.003}; });
  for (std::size_t k = 0; k < s.encoder.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) {
      const double payout = s.without.states[k].cables[i].payout_m;
      EXPECT_NEAR(s.encoder[k][i], s.with.true_robot.effects.encoder_scale[i] * payout, 1e-9);
    }
    EXPECT_EQ(s.force[k], 0.0);
  }
  EXPECT_EQ(s.with.truth.effects.at("encoder_scale").size(), 4u);
}

TEST(SimDataset, GrossErrorsChangeOnlyThePlantedReadingsAndAreListed) {
  // GIVEN the same data set with 10 % gross encoder errors and 10 % force spikes
  DatasetConfig config = noiseless(Preset::kLarge, 20);
  const SimulatedDataset clean = simulate(config);
  config.gross_errors.encoder_fraction = 0.1;
  config.gross_errors.force_fraction = 0.1;
  const SimulatedDataset dirty = simulate(config);
  // THEN truth lists 2 + 2 readings, each off by its listed error within the
  // documented ranges, and every other reading is unchanged
  ASSERT_EQ(dirty.truth.outliers.size(), 4u);
  std::vector<std::array<double, kCableCount + 1>> expected(clean.samples.size());
  for (const SensorReading& o : dirty.truth.outliers) {
    const int slot = o.sensor == SensorKind::kForce ? kCableCount : o.cable;
    expected[o.row][slot] = o.value;
    const double size = std::abs(o.value);
    if (o.sensor == SensorKind::kEncoder) {
      EXPECT_TRUE(size >= 0.5 && size <= 2.0) << size;
    } else {
      EXPECT_TRUE(size >= 50.0 && size <= 500.0) << size;
    }
  }
  for (std::size_t k = 0; k < clean.samples.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) {
      EXPECT_NEAR(dirty.samples[k].encoder_m[i] - clean.samples[k].encoder_m[i], expected[k][i], 1e-9);
    }
    EXPECT_NEAR(dirty.samples[k].force_n - clean.samples[k].force_n, expected[k][kCableCount], 1e-9);
  }
}

TEST(SimDataset, LoadCellBiasAndGainActOnTheTension) {
  // GIVEN a load-cell bias and gain; THEN force = (1 + g) T + b, encoders unchanged
  const Shift s = shift_of([](HiddenEffects& e) {
    e.force_bias_n = 3.0;
    e.force_gain = 0.02;
  });
  for (std::size_t k = 0; k < s.force.size(); ++k) {
    EXPECT_NEAR(s.force[k], 0.02 * s.without.states[k].cables[0].tension_n + 3.0, 1e-9);
    for (double d : s.encoder[k]) EXPECT_EQ(d, 0.0);
  }
}

TEST(SimDataset, ElasticityShortensTheUnstretchedPayout) {
  // GIVEN elastic cables; THEN the encoders, counting unstretched cable, read
  // less than the arc length, by the stretch
  const Shift s = shift_of([](HiddenEffects& e) { e.axial_stiffness_n = 5.0e5; });
  for (std::size_t k = 0; k < s.encoder.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) {
      const CableEquilibrium& c = s.with.states[k].cables[i];
      EXPECT_LT(s.encoder[k][i], 0.0);
      EXPECT_NEAR(s.encoder[k][i], -(c.arc_length_m - c.payout_m), 0.05 * (c.arc_length_m - c.payout_m));
    }
  }
}

TEST(SimDataset, HeavierCableSagsMoreAndPullsHarder) {
  // GIVEN a cable 10 % heavier than nominal; THEN every cable is longer at the same pose and the load cell reads more
  const Shift s = shift_of([](HiddenEffects& e) { e.density_error = 0.1; });
  for (std::size_t k = 0; k < s.encoder.size(); ++k) {
    for (double d : s.encoder[k]) EXPECT_GT(d, 0.0);
    EXPECT_GT(s.force[k], 0.0);
  }
}

TEST(SimDataset, PulleyAddsTheWrappedArc) {
  // GIVEN swivel pulleys of 0.15 m; THEN every encoder reads more (the wrap
  // outweighs the shorter free cable) but by less than the wrap itself
  const Shift s = shift_of([](HiddenEffects& e) { e.pulley_radius_m = 0.15; });
  for (std::size_t k = 0; k < s.encoder.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) {
      EXPECT_GT(s.encoder[k][i], 0.0);
      EXPECT_LT(s.encoder[k][i], s.with.states[k].cables[i].wrapped_arc_m);
    }
  }
}

TEST(SimDataset, WindTowardsPlusXLoadsTheCablesBehind) {
  // GIVEN wind pushing the platform towards +x (away from anchors 0 and 3);
  // THEN the reference cable 0, which holds it back, pulls harder
  const Shift s = shift_of([](HiddenEffects& e) { e.wind_force_world_n = Eigen::Vector3d(20.0, 0.0, 0.0); });
  for (std::size_t k = 0; k < s.force.size(); ++k) EXPECT_GT(s.force[k], 0.0);
  EXPECT_EQ(s.with.truth.effects.at("wind_force"), (std::vector<double>{20.0, 0.0, 0.0}));
}

TEST(SimDataset, OffsetCentreOfMassTiltsThePlatformAndShiftsTheLoad) {
  // GIVEN the true centre of mass 5 cm off towards (-x, -y)
  const Shift s = shift_of([](HiddenEffects& e) { e.com_offset_platform = Eigen::Vector3d(-0.05, -0.05, 0.0); });
  for (std::size_t k = 0; k < s.with.samples.size(); ++k) {
    // THEN the measured orientation tilts and the reference force changes:
    // four taut cables at the corners are stiff against tilting, so the
    // cables' tension split, not the tilt, carries most of the extra moment
    EXPECT_GT(s.with.samples[k].world_R_platform.angularDistance(s.without.samples[k].world_R_platform), 0.005);
    EXPECT_GT(std::abs(s.force[k]), 1.0);
    // AND the positions are unchanged (the platform was put at the same waypoints)
    EXPECT_EQ(s.with.samples[k].position_world, s.without.samples[k].position_world);
  }
  EXPECT_EQ(s.with.truth.effects.at("com_offset").size(), 3u);
}

TEST(SimDataset, NoEffectsMeansEmptyEffectsTableAndEncoderIsArcPlusOffset) {
  // GIVEN no hidden effects, no noise
  const SimulatedDataset data = simulate(noiseless(Preset::kSmall, 3));
  // THEN truth.toml has no [effects] and enc_i = arc length + offset_i (docs/FORMATS.md)
  EXPECT_TRUE(data.truth.effects.empty());
  for (std::size_t k = 0; k < data.samples.size(); ++k) {
    for (int i = 0; i < kCableCount; ++i) {
      EXPECT_NEAR(data.samples[k].encoder_m[i], data.states[k].cables[i].arc_length_m + data.truth.winches[i].offset_m,
                  1e-12);
    }
  }
}

}  // namespace
}  // namespace cdpr::sim

namespace cdpr::sim {
namespace {

TEST(SimDataset, ADesignMeasuresTheMostInformativeOfTheCandidates) {
  // GIVEN the small robot, 8 poses in a wide box, spread evenly or chosen from 60 candidates
  DatasetConfig config = noiseless(Preset::kSmall, 8);
  config.anchor_perturbation_m = 1.0;
  config.workspace_min = Eigen::Vector3d(1.0, 0.5, 2.0);
  config.workspace_max = Eigen::Vector3d(11.5, 4.0, 22.0);
  const SimulatedDataset even = simulate(config);
  config.design_candidates = 60;
  const SimulatedDataset designed = simulate(config);
  // THEN both have 8 samples, and the design's poses allow smaller anchor and offset variances
  ASSERT_EQ(designed.samples.size(), 8u);
  const auto poses = [](const SimulatedDataset& data) {
    std::vector<Pose> p;
    for (const Equilibrium& state : data.states) p.push_back(state.world_T_platform);
    return p;
  };
  EXPECT_LT(design_variance_sum(designed.nominal, poses(designed)), 0.5 * design_variance_sum(even.nominal, poses(even)));
  // AND the samples are the true states of those poses, in sequence order with ids 0..7
  for (std::size_t k = 0; k < designed.samples.size(); ++k) {
    EXPECT_EQ(designed.samples[k].id, static_cast<int>(k));
    EXPECT_LT((designed.samples[k].position_world - designed.states[k].world_T_platform.position_world).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace cdpr::sim
