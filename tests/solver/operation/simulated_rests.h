#pragma once
// Rests of a simulated robot (tools/sim: the true equilibrium of heavy
// cables) and a committed calibration of it: the true anchors and offsets
// with a calibration's typical sigmas, perturbed by those sigmas so the
// priors are honest.

#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "sim/dataset.h"
#include "sim/rest_sequence.h"
#include "solver/model/calibration.h"

namespace cdpr::test {

struct SimulatedRests {
  sim::SimulatedDataset data;
  Calibration calibration;
};

inline SimulatedRests simulated_rests(sim::Preset preset, int count, std::uint64_t seed, double anchor_sigma_m = 2e-3,
                                      double offset_sigma_m = 2e-3) {
  sim::DatasetConfig config;
  config.preset = preset;
  config.pose_count = count;
  config.seed = seed;
  auto data = sim::simulate_dataset(config);
  EXPECT_TRUE(data.has_value());
  SimulatedRests out{std::move(*data), {}};
  std::mt19937_64 rng(seed + 1000);
  std::normal_distribution<double> normal;
  out.calibration.robot = out.data.nominal.name;
  for (int i = 0; i < kCableCount; ++i) {
    WinchCalibration w;
    w.anchor_sigma = Eigen::Vector3d::Constant(anchor_sigma_m);
    w.anchor_world = out.data.truth.winches[i].anchor_world +
                     anchor_sigma_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    w.offset_sigma_m = offset_sigma_m;
    w.offset_m = out.data.truth.winches[i].offset_m + offset_sigma_m * normal(rng);
    out.calibration.winches.push_back(w);
  }
  return out;
}

// A calibration of `truth` good to the given sigmas (perturbed by them).
inline Calibration calibration_of(const Truth& truth, std::uint64_t seed, double anchor_sigma_m,
                                  double offset_sigma_m) {
  std::mt19937_64 rng(seed + 2000);
  std::normal_distribution<double> normal;
  Calibration c;
  for (int i = 0; i < kCableCount; ++i) {
    WinchCalibration w;
    w.anchor_sigma = Eigen::Vector3d::Constant(anchor_sigma_m);
    w.anchor_world = truth.winches[i].anchor_world +
                     anchor_sigma_m * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    w.offset_sigma_m = offset_sigma_m;
    w.offset_m = truth.winches[i].offset_m + offset_sigma_m * normal(rng);
    c.winches.push_back(w);
  }
  return c;
}

// A robot in operation with one fault (sim/rest_sequence.h) and a calibration of it.
struct WatchedRests {
  sim::RestSequence sequence;
  Calibration calibration;
};

inline WatchedRests watched_rests(sim::Preset preset, int count, std::uint64_t seed, sim::InjectedFault fault = {}) {
  sim::RestSequenceConfig config;
  config.robot.preset = preset;
  config.robot.seed = seed;
  config.rest_count = count;
  config.fault = fault;
  auto sequence = sim::simulate_rest_sequence(config);
  EXPECT_TRUE(sequence.has_value());
  WatchedRests out{std::move(*sequence), {}};
  out.calibration = calibration_of(sim::truth_of(out.sequence.true_robot), seed, 2e-3, 2e-3);
  return out;
}

}  // namespace cdpr::test
