#include "rest_mode.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "sim/rest_sequence.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"
#include "src/formats/samples_csv.h"

namespace cdpr::tools {
namespace {

bool write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << text;
  file.close();
  if (!file) std::fprintf(stderr, "cdpr-sim: cannot write %s\n", path.c_str());
  return static_cast<bool>(file);
}

}  // namespace

void add_rest_mode_options(CLI::App& app, RestModeArgs& args) {
  app.add_option("--rests", args.rests,
                 "operation instead of calibration: this many rests at random workspace points (samples.csv), "
                 "with true_poses.csv beside it and the --fault injected (docs/operation.md)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--fault", args.fault, "with --rests: none, slip (encoder offset + size m), anchor (moved size m), "
                                        "creep (size m longer at its payout, over --creep-rests), payload (+size kg)")
      ->check(CLI::IsMember({"none", "slip", "anchor", "creep", "payload"}))->capture_default_str();
  app.add_option("--fault-cable", args.fault_cable, "the fault's cable (slip, anchor, creep)")->check(CLI::Range(0, 3));
  app.add_option("--fault-size", args.fault_size, "the fault's size [m, or kg for payload]");
  app.add_option("--fault-from", args.fault_from, "the first rest with the fault")->check(CLI::NonNegativeNumber);
  app.add_option("--fault-com", args.fault_com, "payload: the centre of mass moves by x,y,z [m, platform frame]");
  app.add_option("--creep-rests", args.creep_rests, "creep: rests until it reaches its size")
      ->check(CLI::PositiveNumber)->capture_default_str();
}

int run_rest_mode(const sim::DatasetConfig& config, const RestModeArgs& args, const std::filesystem::path& dir) {
  sim::RestSequenceConfig rc;
  rc.robot = config;
  rc.rest_count = args.rests;
  rc.fault.kind = *sim::parse_fault_kind(args.fault);
  rc.fault.cable = args.fault_cable;
  rc.fault.size = args.fault_size;
  rc.fault.from_rest = args.fault_from;
  rc.fault.ramp_rests = args.creep_rests;
  if (!args.fault_com.empty()) {
    std::istringstream in(args.fault_com);
    char c1 = 0, c2 = 0;
    Eigen::Vector3d v;
    if (!(in >> v.x() >> c1 >> v.y() >> c2 >> v.z()) || c1 != ',' || c2 != ',') {
      std::fprintf(stderr, "cdpr-sim: --fault-com: expected x,y,z\n");
      return 1;
    }
    rc.fault.com_shift_platform = v;
  }
  const auto sequence = sim::simulate_rest_sequence(rc);
  if (!sequence) {
    std::fprintf(stderr, "cdpr-sim: %s\n", sequence.error().c_str());
    return 2;
  }
  std::vector<Sample> true_poses = sequence->rests;
  for (std::size_t k = 0; k < true_poses.size(); ++k) {
    true_poses[k].position_world = sequence->states[k].world_T_platform.position_world;
    true_poses[k].world_R_platform = sequence->states[k].world_T_platform.world_R_platform;
  }
  if (!write(dir / "robot.toml", formats::format_robot_toml(sequence->nominal)) ||
      !write(dir / "samples.csv", formats::format_samples_csv(sequence->rests)) ||
      !write(dir / "true_poses.csv", formats::format_samples_csv(true_poses)) ||
      !write(dir / "truth.toml", formats::format_truth_toml(sim::truth_of(sequence->true_robot))) ||
      !write(dir / "truth_after.toml",
             formats::format_truth_toml(sim::truth_of(
                 sim::robot_at_rest(*sequence, rc.fault, static_cast<int>(sequence->rests.size()) - 1))))) {
    return 1;
  }
  std::printf("wrote %s: %zu rests, fault %s", (dir / "samples.csv").c_str(), sequence->rests.size(),
              args.fault.c_str());
  if (rc.fault.kind != sim::FaultKind::kNone) {
    std::printf(" of size %g on cable %d from rest %d", args.fault_size, args.fault_cable, args.fault_from);
    if (rc.fault.kind == sim::FaultKind::kAnchorMoved) {
      const Eigen::Vector3d& d = sequence->anchor_shift_world;
      std::printf(" (anchor moved by %.4f %.4f %.4f m)", d.x(), d.y(), d.z());
    }
  }
  std::printf("\n");
  return 0;
}

}  // namespace cdpr::tools
