#include "sim/rest_sequence.h"

#include <algorithm>

#include "sim/rng.h"
#include "sim/sensors.h"
#include "sim/waypoints.h"

namespace cdpr::sim {
namespace {

// Streams of their own, so the rests differ from the calibration's poses of
// the same seed, and the fault's direction from both.
constexpr std::uint64_t kRestWaypointSeedSalt = 0x7e57'0000'0000ULL;
constexpr std::uint64_t kStreamRestNoise = 41;
constexpr std::uint64_t kStreamFaultDirection = 42;

Eigen::Vector3d random_direction(Rng& rng) {
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal());
  } while (v.norm() < 1e-12);
  return v.normalized();
}

bool rest_is_taut(const Equilibrium& state, double min_tension_n) {
  return std::all_of(state.cables.begin(), state.cables.end(),
                     [&](const CableEquilibrium& c) { return c.tension_n >= min_tension_n; });
}

}  // namespace

std::optional<FaultKind> parse_fault_kind(std::string_view name) {
  if (name == "none") return FaultKind::kNone;
  if (name == "slip") return FaultKind::kEncoderSlip;
  if (name == "anchor") return FaultKind::kAnchorMoved;
  if (name == "creep") return FaultKind::kCableCreep;
  if (name == "payload") return FaultKind::kPayloadChange;
  return std::nullopt;
}

TrueRobot robot_at_rest(const RestSequence& sequence, const InjectedFault& fault, int k) {
  TrueRobot robot = sequence.true_robot;
  if (fault.kind == FaultKind::kNone || k < fault.from_rest) return robot;
  switch (fault.kind) {
    case FaultKind::kEncoderSlip: robot.encoder_offset_m[fault.cable] += fault.size; break;
    case FaultKind::kAnchorMoved: robot.robot.winches[fault.cable].anchor_world += sequence.anchor_shift_world; break;
    case FaultKind::kCableCreep: {
      const double payout = sequence.states.size() > static_cast<std::size_t>(fault.from_rest)
                                ? sequence.states[fault.from_rest].cables[fault.cable].payout_m
                                : 1.0;
      const double progress = std::min(1.0, static_cast<double>(k - fault.from_rest + 1) / std::max(1, fault.ramp_rests));
      // Longer than counted: the reading is (1 + s) times the true payout, s < 0.
      robot.effects.encoder_scale[fault.cable] -= progress * fault.size / payout;
      break;
    }
    case FaultKind::kPayloadChange:
      robot.robot.platform_mass_kg += fault.size;
      robot.effects.com_offset_platform += fault.com_shift_platform;
      break;
    case FaultKind::kNone: break;
  }
  return robot;
}

Expected<RestSequence, std::string> simulate_rest_sequence(const RestSequenceConfig& config) {
  if (config.rest_count < 1) return Unexpected{std::string("rest count must be at least 1")};
  if (config.fault.cable < 0 || config.fault.cable >= kCableCount) {
    return Unexpected{std::string("the fault's cable must be 0 to 3")};
  }
  // The nominal robot.toml and the true robot of the seed, as the calibration data set's.
  DatasetConfig one = config.robot;
  one.pose_count = 1;
  auto base = simulate_dataset(one);
  if (!base) return Unexpected{base.error()};
  RestSequence out;
  out.nominal = base->nominal;
  out.true_robot = base->true_robot;
  Rng direction = Rng::stream(config.robot.seed, kStreamFaultDirection);
  const Eigen::Vector3d& chosen = config.fault.direction_world;
  out.anchor_shift_world = config.fault.size * (chosen.norm() > 0.0 ? chosen.normalized() : random_direction(direction));

  const PresetSpec spec = preset_spec(config.robot.preset);
  WaypointSequence waypoints(spec, config.robot.seed ^ kRestWaypointSeedSalt);
  SolverOptions options;
  options.segments = config.robot.segments;
  const int max_tries = config.rest_count * config.robot.max_candidates_per_pose;
  for (int tried = 0; static_cast<int>(out.rests.size()) < config.rest_count; ++tried) {
    if (tried == max_tries) return Unexpected{std::string("too few rests with a taut equilibrium")};
    const int k = static_cast<int>(out.rests.size());
    const TrueRobot robot = robot_at_rest(out, config.fault, k);
    const Waypoint w = waypoints.next();
    const EquilibriumResult state = solve_equilibrium(robot, w.position_world, w.yaw_rad, options);
    if (!state || !rest_is_taut(*state, spec.min_tension_n)) continue;
    // The creep's payout reference is the fault's first rest, known only once it exists.
    out.states.push_back(*state);
    TrueRobot measured_by = robot;
    if (config.fault.kind == FaultKind::kCableCreep && k >= config.fault.from_rest) {
      measured_by = robot_at_rest(out, config.fault, k);
    }
    Rng noise = Rng::stream(config.robot.seed, kStreamRestNoise, static_cast<std::uint64_t>(w.candidate));
    out.rests.push_back(measure(measured_by, *state, config.robot.noise_scale, noise, k));
  }
  return out;
}

}  // namespace cdpr::sim
