#include "virtual-robot/virtual_robot.h"

#include <poll.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "drivers/can/fd_can_transport.h"
#include "drivers/pose/pose_line.h"
#include "sim/sensors.h"
#include "sim/stream_purpose.h"
#include "virtual-robot/modbus_rtu_server.h"
#include "virtual-robot/modbus_tcp_server.h"
#include "solver/nls/pose.h"
#include "src/formats/calibration_toml.h"
#include "src/formats/robot_toml.h"

namespace cdpr::virtual_robot {
namespace {

// A stream of its own for the live sensor noise (sim/stream_purpose.h uses 1-5).
constexpr std::uint64_t kStreamLiveNoise = 101;
// And one for the production controller's jobs (operation).
constexpr std::uint64_t kStreamJobs = 102;

bool write_file(const std::string& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << text;
  file.close();
  return static_cast<bool>(file);
}

}  // namespace

sim::DatasetConfig dataset_config(const VirtualRobotOptions& options) {
  // The simulator's own data-set builder gives the true robot (random true
  // offsets) and the nominal robot.toml exactly as cdpr-sim would.
  sim::DatasetConfig config;
  config.preset = options.preset;
  config.seed = options.seed;
  config.pose_count = 1;
  config.anchor_perturbation_m = options.anchor_perturbation_m;
  config.noise_scale = options.noise_scale;
  config.segments = options.physics.segments;
  config.effects = options.effects;
  return config;
}

Eigen::Vector3d start_position_world(sim::Preset preset) {
  const sim::PresetSpec spec = sim::preset_spec(preset);
  return 0.5 * (spec.workspace_min + spec.workspace_max);
}

Expected<std::unique_ptr<VirtualRobot>, std::string> VirtualRobot::create(const VirtualRobotOptions& options) {
  if (!(options.time_scale > 0.0)) return Unexpected{std::string("time scale must be > 0")};
  if (std::string why = CanopenNodes::check(options.nodes); !why.empty()) return Unexpected{"CANopen nodes: " + why};
  auto data = sim::simulate_dataset(dataset_config(options));
  if (!data) return Unexpected{"simulated robot: " + data.error()};
  auto robot = std::unique_ptr<VirtualRobot>(new VirtualRobot(options, std::move(*data)));

  auto physics =
      RobotPhysics::at_rest(robot->data_.true_robot, start_position_world(options.preset), options.physics);
  if (!physics) return Unexpected{physics.error()};
  robot->physics_ = std::make_unique<RobotPhysics>(std::move(*physics));

  NodeLayout nodes = options.nodes;
  nodes.encoder_noise_m = options.noise_scale * robot->data_.true_robot.robot.noise.encoder_m;
  const hal::TimeUs now_us = robot->clock_.now_us();
  hal::Status clock_status;
  robot->robot_clock_ = drivers::SharedClock::create(options.dir + "/clock", now_us, clock_status);
  if (!robot->robot_clock_) return Unexpected{clock_status.to_string()};
  robot->nodes_ = std::make_unique<CanopenNodes>(nodes, *robot->physics_,
                                                 sim::Rng::stream(options.seed, kStreamLiveNoise, 1), now_us);
  robot->start_us_ = robot->last_us_ = robot->next_pose_us_ = now_us;
  if (options.operation.enabled) {
    std::array<double, kCableCount> payout_m{};
    for (int i = 0; i < kCableCount; ++i) payout_m[i] = robot->physics_->payout_m(i);
    robot->controller_ = std::make_unique<ProductionController>(
        options.operation, robot->data_.true_robot, options.preset, nodes, options.physics.segments,
        sim::Rng::stream(options.seed, kStreamJobs), payout_m);
  }
  robot->fault_schedule_ = std::make_unique<FaultSchedule>(options.faults);
  if (!options.frame_log_path.empty()) {
    robot->frame_log_ = std::fopen(options.frame_log_path.c_str(), "w");
    if (robot->frame_log_ == nullptr) return Unexpected{"cannot write the frame log " + options.frame_log_path};
  }

  auto can = StreamListener::listen(options.dir + "/can.sock");
  if (!can.ok()) return Unexpected{"CAN socket: " + can.status().to_string()};
  robot->can_ = std::move(can.value());
  auto pose = StreamListener::listen(options.dir + "/pose.sock");
  if (!pose.ok()) return Unexpected{"pose socket: " + pose.status().to_string()};
  robot->pose_ = std::move(pose.value());
  robot->cell_ = std::make_unique<VirtualLoadCell>(options.load_cell);
  std::string ready = "modbus_endpoint = \"";
  if (options.modbus_rtu) {
    auto rtu = ModbusRtuServer::open(options.dir + "/load_cell.tty", *robot->cell_);
    if (!rtu.ok()) return Unexpected{"load cell: " + rtu.status().to_string()};
    robot->modbus_ = std::move(rtu.value());
    ready += robot->modbus_->endpoint() + "\"\n";
  } else {
    auto tcp = ModbusTcpServer::listen(options.modbus_port, *robot->cell_);
    if (!tcp.ok()) return Unexpected{"load cell: " + tcp.status().to_string()};
    ready += tcp.value()->endpoint() + "\"\nmodbus_port = " + std::to_string(tcp.value()->port()) + "\n";
    robot->modbus_ = std::move(tcp.value());
  }
  robot->publish(now_us);

  // drive.eds, encoder.eds: the EDS files its nodes play, for the daemon's [winches.drive|encoder] eds.
  if (!write_file(options.dir + "/robot.toml", formats::format_robot_toml(robot->data_.nominal)) ||
      !write_file(options.dir + "/truth.toml", formats::format_truth_toml(robot->data_.truth)) ||
      !write_file(options.dir + "/drive.eds", options.nodes.drive_eds.text) ||
      !write_file(options.dir + "/encoder.eds", options.nodes.encoder_eds.text) ||
      !write_file(options.dir + "/ready", ready)) {
    return Unexpected{"cannot write robot.toml, truth.toml, the EDS files or ready in " + options.dir};
  }
  return robot;
}

VirtualRobot::VirtualRobot(const VirtualRobotOptions& options, sim::SimulatedDataset data)
    : options_(options), data_(std::move(data)), noise_(sim::Rng::stream(options.seed, kStreamLiveNoise, 0)) {}

VirtualRobot::~VirtualRobot() {
  if (frame_log_ != nullptr) std::fclose(frame_log_);
}

void VirtualRobot::run(const std::atomic<bool>& stop) {
  while (!stop.load()) run_once(2'000);
}

void VirtualRobot::run_once(hal::TimeUs max_wait_us) {
  follow_pose_fault();
  follow_can_fault();
  fds_.clear();
  if (can_) can_->append_poll_fds(fds_);
  if (pose_) pose_->append_poll_fds(fds_);
  modbus_->append_poll_fds(fds_);
  const int ready = poll(fds_.data(), fds_.size(), static_cast<int>(max_wait_us / 1000));
  if (ready > 0) {
    if (can_) can_->service(fds_, [this](int client, std::string_view bytes) { on_can_bytes(client, bytes); });
    if (pose_) pose_->service(fds_, [](int, std::string_view) {});  // the pose stream is one-way
  }
  const hal::TimeUs now_us = clock_.now_us();
  modbus_->service(fds_, now_us);  // also sends replies whose latency has passed
  // Catching up a long gap would take more solves than the gap had time
  // for: starved of CPU, the process would fall further behind every pass.
  const double elapsed_s = options_.time_scale * 1e-6 * static_cast<double>(now_us - last_us_);
  const double step_s = std::min(elapsed_s, kMaxSolvesPerPass * longest_step_s());
  robot_time_s_ += step_s;
  advance(step_s);
  last_us_ = now_us;
  robot_clock_->advance_to(robot_clock_us());
  for (int i = 0; i < kCableCount; ++i) payout_snapshot_m_[i].store(physics_->payout_m(i));
  operate();
  publish(robot_clock_->now_us());
}

void VirtualRobot::operate() {
  std::vector<std::string> began;
  fault_schedule_->apply(robot_time_s_, *physics_, *nodes_, began);
  for (const std::string& fault : began) {
    std::printf("virtual-robot: at %.1f s (robot time): %s\n", robot_time_s_, fault.c_str());
    std::fflush(stdout);
  }
  if (!controller_) return;
  const std::size_t before = controller_frames_.size();
  controller_->step(robot_time_s_, *nodes_, controller_frames_);
  // The controller's frames reach the nodes as they would on the wire.
  const hal::TimeUs now_us = robot_clock_->now_us();
  for (std::size_t k = before; k < controller_frames_.size(); ++k) nodes_->on_frame(controller_frames_[k], now_us);
}

hal::TimeUs VirtualRobot::robot_clock_us() const {
  return start_us_ + static_cast<hal::TimeUs>(1e6 * robot_time_s_ / options_.time_scale);
}

double VirtualRobot::robot_time_lost_s() const {
  return options_.time_scale * 1e-6 * static_cast<double>(last_us_ - start_us_) - robot_time_s_;
}

double VirtualRobot::longest_step_s() const { return std::max(1e-3, options_.physics.equilibrium_interval_s); }

void VirtualRobot::advance(double dt_s) {
  // A long step (a gap magnified by the time scale) is simulated in steps no
  // longer than the physics' equilibrium interval. In one step the drives
  // would move metres at once, the taut solve would start far from the new
  // rest pose and find none, and the platform would hang on three cables
  // for a moment: a load cell reading 0 N mid-move.
  const int steps = std::max(1, static_cast<int>(std::ceil(dt_s / longest_step_s())));
  for (int k = 0; k < steps; ++k) {
    nodes_->advance(dt_s / steps);
    physics_->advance(dt_s / steps);
    watched_s_ += dt_s / steps;
    const Eigen::Vector3d& platform = physics_->pose().position_world;
    stops_.step(watched_s_, nodes_->any_drive_braking(), nodes_->axes_still(), platform,
                physics_->velocity_mps().norm(), (platform - physics_->rest().world_T_platform.position_world).norm());
  }
  if (options_.report_stops && stops_.take_finished()) {
    const StopReport& r = *stops_.latest();
    std::printf("virtual-robot: stop at %.1f s (robot time), platform at %.2f m/s: cables at rest after %.2f s, "
                "platform up to %.2f m from where the stop began (%.1f s after it), %s %.2f m from it after %.1f s\n",
                r.began_s, r.speed_mps, r.cables_stopped_s - r.began_s, r.largest_m, r.largest_at_s - r.began_s,
                r.settled ? "at rest" : "still swinging at the next move,", r.from_start_m, watched_s_ - r.began_s);
    std::fflush(stdout);
  }
}

void VirtualRobot::on_can_bytes(int client, std::string_view bytes) {
  std::string& partial = can_partial_[client];
  partial.append(bytes);
  // On a faulted bus the master's frames never reach the nodes; they are counted all the same.
  const bool delivered = can_fault_.load() == DeviceFault::kNone;
  std::size_t used = 0;
  for (; partial.size() - used >= drivers::can::kWireFrameBytes; used += drivers::can::kWireFrameBytes) {
    drivers::can::CanFrame frame;
    if (drivers::can::decode_wire_frame(reinterpret_cast<const std::uint8_t*>(partial.data() + used), frame)) {
      log_client_frame(frame);
      if (delivered) nodes_->on_frame(frame, robot_clock_->now_us());
    }
  }
  partial.erase(0, used);
}

void VirtualRobot::log_client_frame(const drivers::can::CanFrame& frame) {
  ++frames_from_clients_;
  if (frame_log_ == nullptr) return;
  std::fprintf(frame_log_, "%lld %03X %u", static_cast<long long>(robot_clock_->now_us()), frame.id, frame.len);
  for (int k = 0; k < frame.len && k < 8; ++k) std::fprintf(frame_log_, " %02X", frame.data[k]);
  std::fputc('\n', frame_log_);
  std::fflush(frame_log_);
}

void VirtualRobot::publish(hal::TimeUs now_us) {
  frames_.clear();
  // The production controller's frames are on the bus too, before the answers they caused.
  frames_.insert(frames_.end(), controller_frames_.begin(), controller_frames_.end());
  controller_frames_.clear();
  nodes_->poll(now_us, frames_);
  std::uint8_t wire[drivers::can::kWireFrameBytes];
  std::string bytes;
  const DeviceFault can_fault = can_fault_.load();
  for (drivers::can::CanFrame frame : frames_) {
    if (can_fault == DeviceFault::kSilent || can_fault == DeviceFault::kDisconnected) break;
    if (can_fault == DeviceFault::kGarbage) {
      for (std::uint8_t& byte : frame.data) byte ^= 0x5A;
    }
    drivers::can::encode_wire_frame(frame, wire);
    bytes.append(reinterpret_cast<const char*>(wire), sizeof(wire));
  }
  if (!bytes.empty() && can_) can_->broadcast(bytes);

  const Robot& robot = data_.true_robot.robot;
  const double k = options_.noise_scale;
  // Load cell: the cell calls its reading stable once it stops changing.
  const int reference = robot.reference_cable;
  const bool winches_still = nodes_->winches_still();
  cell_->set_reading(sim::force_reading_n(data_.true_robot.effects, physics_->tension_n(reference)) +
                         k * robot.noise.force_n * noise_.normal(),
                     winches_still && physics_->tension_unsettled_n(reference) < std::max(1.0, robot.noise.force_n),
                     false);
  publish_pose(now_us);
}

void VirtualRobot::follow_pose_fault() {
  const bool disconnected = pose_fault_.load() == DeviceFault::kDisconnected;
  if (disconnected && pose_) pose_.reset();  // closes every client, removes the socket
  if (!disconnected && !pose_) {
    auto pose = StreamListener::listen(options_.dir + "/pose.sock");
    if (pose.ok()) pose_ = std::move(pose.value());
  }
}

void VirtualRobot::follow_can_fault() {
  const bool disconnected = can_fault_.load() == DeviceFault::kDisconnected;
  if (disconnected && can_) {
    can_.reset();  // closes every client, removes the socket
    can_partial_.clear();
  }
  if (!disconnected && !can_) {
    auto can = StreamListener::listen(options_.dir + "/can.sock");
    if (can.ok()) can_ = std::move(can.value());
  }
}

void VirtualRobot::publish_pose(hal::TimeUs now_us) {
  if (now_us < next_pose_us_) return;
  next_pose_us_ += static_cast<hal::TimeUs>(1e6 / options_.pose_rate_hz);
  if (next_pose_us_ < now_us) next_pose_us_ = now_us;  // after a stall: no burst of old poses
  const Robot& robot = data_.true_robot.robot;
  const double k = options_.noise_scale;
  const Pose& truth = physics_->pose();
  const Eigen::Vector3d position =
      truth.position_world + k * robot.noise.position_m * Eigen::Vector3d(noise_.normal(), noise_.normal(), noise_.normal());
  const Eigen::Quaterniond rotation =
      truth.world_R_platform *
      so3_exp(k * robot.noise.orientation_rad * Eigen::Vector3d(noise_.normal(), noise_.normal(), noise_.normal()));
  hal::PoseSample sample;
  sample.platform_world = {position.x(), position.y(), position.z()};
  sample.world_R_platform = {rotation.w(), rotation.x(), rotation.y(), rotation.z()};
  sample.valid = true;
  // The robot's own clock: the time its physics has run, so that speeds
  // over the stamps are the platform's, also while it ran slow.
  sample.source_time_us = start_us_ + static_cast<hal::TimeUs>(1e6 * robot_time_s_);
  const DeviceFault fault = pose_fault_.load();
  if (!pose_ || fault == DeviceFault::kSilent) return;
  pose_->broadcast(fault == DeviceFault::kGarbage ? std::string("\x01\x02 not a pose %%\n")
                                                  : drivers::pose::format_pose_line(sample));
}

}  // namespace cdpr::virtual_robot
