#pragma once
// The virtual robot: a simulated cable robot that speaks the real robot's
// protocols, so cdpr-calibd runs against it unchanged but for its endpoints
// (docs/DESIGN.md "Where this runs").
//
//   <dir>/can.sock    CAN frames over a Unix stream socket (the record format
//                     of drivers/can/fd_can_transport.h): 4 CiA 402 drives and
//                     4 CiA 406 encoders from their profiles' defaults, which
//                     the daemon configures over SDO (canopen_nodes.h)
//   127.0.0.1:<port>  Modbus TCP load cell on the reference cable, or with
//   <dir>/load_cell.tty  modbus_transport "rtu" a Modbus RTU one on a pty;
//                     register map per load_cell_model (load_cell_models.h)
//   <dir>/pose.sock   pose stream (drivers/pose/pose_line.h) at pose_rate_hz
//   <dir>/robot.toml  the NOMINAL robot (anchors perturbed), for the daemon
//   <dir>/truth.toml  the truth (anchors, encoder offsets), for comparison
//   <dir>/ready       "modbus_endpoint = <endpoint>" and, on TCP,
//                     "modbus_port = <port>", written once everything listens
//
// Physics (robot_physics.h) from the simulator's true equilibrium, with the
// options' hidden effects; sensor noise per the preset (robot.toml [noise])
// on every single reading.
//   <dir>/clock       the robot's clock (drivers/clock/shared_clock.h), below
//
// Time: simulated time runs time_scale times faster than the monotonic
// clock (drive speeds, settling). A process starved of CPU does not jump:
// one run_once() simulates at most kMaxSolvesPerPass equilibrium intervals,
// so simulated time then runs slower than time_scale (a slower robot, its
// pose stamps too) and the work of a pass stays bounded. The robot's clock
// is that simulated time divided by time_scale: the monotonic clock while
// the process keeps up, slower while it is starved. The devices' heartbeats,
// PDO event timers, heartbeat consumers and the pose rate run on it, and a
// daemon given it (cdpr-calibd --sim-clock <dir>/clock, or clock() in one
// process) counts its timeouts on it: a robot starved of CPU is a slower
// robot, not a silent node, so a test's verdict does not depend on how
// loaded the machine is. Not thread-safe: one thread calls
// run_once()/run(); clock() may be read from any thread.

#include <array>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "drivers/clock/monotonic_clock.h"
#include "drivers/clock/shared_clock.h"
#include "sim/dataset.h"
#include "sim/presets.h"
#include "sim/rng.h"
#include "src/formats/expected.h"
#include "virtual-robot/canopen_nodes.h"
#include "virtual-robot/modbus_transport.h"
#include "virtual-robot/operation_faults.h"
#include "virtual-robot/production_controller.h"
#include "virtual-robot/virtual_load_cell.h"
#include "virtual-robot/robot_physics.h"
#include "virtual-robot/stop_excursion.h"
#include "virtual-robot/stream_listener.h"

namespace cdpr::virtual_robot {

struct VirtualRobotOptions {
  sim::Preset preset = sim::Preset::kLarge;
  std::uint64_t seed = 1;
  double time_scale = 1.0;            // simulated seconds per real second
  double anchor_perturbation_m = 1.0; // nominal anchors of robot.toml = truth + this [m]
  double noise_scale = 1.0;           // multiplies every sensor sigma
  std::string dir;                    // sockets and files (must exist)
  bool modbus_rtu = false;            // RTU on <dir>/load_cell.tty instead of TCP
  int modbus_port = 0;                // TCP; 0: any free port
  LoadCellServerOptions load_cell;    // register map, unit id, reply latency
  double pose_rate_hz = 100.0;
  PhysicsOptions physics;
  NodeLayout nodes;                   // encoder noise is set from the preset
  // Hidden effects of the true robot (sim/true_robot.h), absent by default;
  // robot.toml never describes them, truth.toml lists them under [effects].
  // Elastic cables (axial_stiffness_n) stretch in the physics while the
  // encoders count unstretched cable; the load cell reads (1 + force_gain) *
  // tension + force_bias_n. Other effects change the physics the same way as
  // in cdpr-sim.
  sim::HiddenEffects effects;
  // Print a line to stdout when the platform came to rest after a stop
  // (stop_excursion.h: its largest excursion, where it rests).
  bool report_stops = false;
  // In operation (production_controller.h): the robot's own controller
  // owns the drives and moves the platform by itself; `faults` happen at
  // their times (operation_faults.h).
  OperationOptions operation;
  std::vector<OperationFault> faults;
  // Every frame a bus client (the daemon) sends is logged here, one line
  // each ("<robot clock us> <id hex> <len> <data hex>"); empty: not logged.
  // frames_from_clients() counts them either way.
  std::string frame_log_path;
};

// The simulated data set behind a virtual robot made with `options` (the
// simulator's builder, as cdpr-sim, one pose): its true robot (true anchors
// and encoder offsets) and the nominal robot of robot.toml.
sim::DatasetConfig dataset_config(const VirtualRobotOptions& options);
// Where the platform rests when a virtual robot of `preset` starts: the
// middle of the preset's workspace [m, world].
Eigen::Vector3d start_position_world(sim::Preset preset);

class VirtualRobot {
 public:
  static constexpr int kMaxSolvesPerPass = 4;

  static Expected<std::unique_ptr<VirtualRobot>, std::string> create(const VirtualRobotOptions& options);
  ~VirtualRobot();

  // Serves the sockets for at most max_wait_us, then advances the physics to
  // now and publishes what is due.
  void run_once(hal::TimeUs max_wait_us);
  // run_once() until `stop` becomes true.
  void run(const std::atomic<bool>& stop);
  // Moves the drives and the physics on by dt_s of simulated time, as
  // run_once() does from the clock (tests choose the steps).
  void advance(double dt_s);
  // Robot time the passes left out while the process was starved of CPU
  // (beyond kMaxSolvesPerPass intervals a pass): how much slower than its
  // time scale this robot ran.
  double robot_time_lost_s() const;
  // The robot's clock (above), readable from any thread, also as <dir>/clock.
  const hal::Clock& clock() const { return *robot_clock_; }

  std::string can_endpoint() const { return "unix:" + options_.dir + "/can.sock"; }
  std::string pose_endpoint() const { return "unix:" + options_.dir + "/pose.sock"; }
  std::string modbus_endpoint() const { return modbus_->endpoint(); }
  const VirtualRobotOptions& options() const { return options_; }
  double time_scale() const { return options_.time_scale; }
  const Robot& nominal_robot() const { return data_.nominal; }
  const Truth& truth() const { return data_.truth; }
  const RobotPhysics& physics() const { return *physics_; }
  // The platform after the latest stop (stop_excursion.h), watched in advance().
  const StopExcursion& stops() const { return stops_; }
  // Winch i's payout [m] as of the last run_once(), readable from any thread.
  double payout_snapshot_m(int winch) const { return payout_snapshot_m_[winch].load(); }
  CanopenNodes& nodes() { return *nodes_; }
  // CAN frames received from the bus's clients (the daemon) since the
  // start, whatever the bus fault (any thread).
  std::uint64_t frames_from_clients() const { return frames_from_clients_.load(); }
  // The production controller in operation (null otherwise); read it only
  // from the thread that runs the robot, or after it stopped.
  const ProductionController* controller() const { return controller_.get(); }
  VirtualLoadCell& load_cell() { return *cell_; }
  // The pose stream's fault (any thread): kSilent stops sending, kGarbage
  // sends lines that are not poses, kDisconnected closes the socket.
  void set_pose_fault(DeviceFault fault) { pose_fault_.store(fault); }
  // The CAN bus's fault (any thread), both directions at once as a cut or
  // shorted bus: kSilent carries no frame either way, kDisconnected closes
  // the CAN socket, kGarbage delivers every node's frame with its data
  // bytes corrupted and nothing of the master's. The drives then see no
  // master heartbeat and react per their 0x6007.
  void set_can_fault(DeviceFault fault) { can_fault_.store(fault); }

 private:
  VirtualRobot(const VirtualRobotOptions& options, sim::SimulatedDataset data);
  // The longest step advance() takes: the physics' equilibrium interval.
  double longest_step_s() const;
  // The robot's clock now: the simulated time run so far, divided by time_scale.
  hal::TimeUs robot_clock_us() const;
  void publish(hal::TimeUs now_us);
  void on_can_bytes(int client, std::string_view bytes);
  // Counts (and logs, with frame_log_path) a frame from a bus client.
  void log_client_frame(const drivers::can::CanFrame& frame);
  void publish_pose(hal::TimeUs now_us);
  // Closes or reopens the pose socket as pose_fault_ says.
  void follow_pose_fault();
  // Closes or reopens the CAN socket as can_fault_ says.
  void follow_can_fault();
  // The production controller's and the faults' turn (operation).
  void operate();

  VirtualRobotOptions options_;
  sim::SimulatedDataset data_;
  drivers::MonotonicClock clock_;
  std::unique_ptr<drivers::SharedClock> robot_clock_;
  sim::Rng noise_;
  std::unique_ptr<RobotPhysics> physics_;
  std::unique_ptr<CanopenNodes> nodes_;
  StopExcursion stops_;
  double watched_s_ = 0.0;  // robot time advance() has simulated
  std::unique_ptr<StreamListener> can_;
  std::unique_ptr<StreamListener> pose_;
  std::unique_ptr<VirtualLoadCell> cell_;
  std::unique_ptr<ModbusTransport> modbus_;
  std::atomic<DeviceFault> pose_fault_{DeviceFault::kNone};
  std::atomic<DeviceFault> can_fault_{DeviceFault::kNone};
  std::array<std::atomic<double>, kCableCount> payout_snapshot_m_{};
  std::map<int, std::string> can_partial_;  // per CAN client: bytes of an incomplete record
  hal::TimeUs last_us_ = 0;
  double robot_time_s_ = 0.0;  // simulated by run_once() since the start: the pose stamps' clock
  hal::TimeUs start_us_ = 0;
  hal::TimeUs next_pose_us_ = 0;
  std::vector<drivers::can::CanFrame> frames_;
  std::vector<pollfd> fds_;
  std::unique_ptr<ProductionController> controller_;
  std::unique_ptr<FaultSchedule> fault_schedule_;
  std::vector<drivers::can::CanFrame> controller_frames_;  // sent this pass, onto the bus with the nodes' frames
  std::atomic<std::uint64_t> frames_from_clients_{0};
  std::FILE* frame_log_ = nullptr;
};

}  // namespace cdpr::virtual_robot
