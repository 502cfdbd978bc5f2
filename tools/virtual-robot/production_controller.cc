#include "virtual-robot/production_controller.h"

#include <algorithm>
#include <cmath>

#include "sim/equilibrium.h"

namespace cdpr::virtual_robot {
namespace {

constexpr std::uint16_t kControlwordEnable = 0x000F;         // enable operation
constexpr std::uint16_t kControlwordNewSetpoint = 0x003F;    // + new set-point, change immediately
constexpr double kHandshakeS = 0.05;  // bit 4 held high this long: the drive acknowledges within a PDO cycle
constexpr int kTries = 8;             // targets drawn before a move is given up for now

drivers::can::CanFrame sdo_write(int node, std::uint16_t index, std::uint8_t subindex, std::uint32_t value) {
  drivers::can::CanFrame f;
  f.id = 0x600 + static_cast<std::uint32_t>(node);
  f.len = 8;
  f.data = {0x22, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), subindex,
            static_cast<std::uint8_t>(value), static_cast<std::uint8_t>(value >> 8),
            static_cast<std::uint8_t>(value >> 16), static_cast<std::uint8_t>(value >> 24)};
  return f;
}

drivers::can::CanFrame nmt_start(int node) {
  drivers::can::CanFrame f;
  f.id = 0x000;
  f.len = 2;
  f.data[0] = 0x01;
  f.data[1] = static_cast<std::uint8_t>(node);
  return f;
}

drivers::can::CanFrame rpdo1(int node, std::uint16_t controlword, std::int32_t target) {
  drivers::can::CanFrame f;
  f.id = 0x200 + static_cast<std::uint32_t>(node);
  f.len = 6;
  const auto t = static_cast<std::uint32_t>(target);
  f.data = {static_cast<std::uint8_t>(controlword), static_cast<std::uint8_t>(controlword >> 8),
            static_cast<std::uint8_t>(t), static_cast<std::uint8_t>(t >> 8), static_cast<std::uint8_t>(t >> 16),
            static_cast<std::uint8_t>(t >> 24), 0, 0};
  return f;
}

// One PDO: invalidated, mapped, typed, timed and valid again (CiA 301's order).
void configure_pdo(int node, std::uint16_t communication, std::uint32_t cob_id,
                   const std::vector<std::uint32_t>& mapping, bool transmit, std::vector<drivers::can::CanFrame>& out) {
  const auto map_index = static_cast<std::uint16_t>(communication + 0x200);
  out.push_back(sdo_write(node, communication, 1, 0x80000000u | cob_id));
  out.push_back(sdo_write(node, map_index, 0, 0));
  for (std::size_t k = 0; k < mapping.size(); ++k) {
    out.push_back(sdo_write(node, map_index, static_cast<std::uint8_t>(k + 1), mapping[k]));
  }
  out.push_back(sdo_write(node, map_index, 0, static_cast<std::uint32_t>(mapping.size())));
  out.push_back(sdo_write(node, communication, 2, 254));
  if (transmit) {
    out.push_back(sdo_write(node, communication, 3, 50));  // inhibit time [100 us]: a changing value at most every 5 ms
    out.push_back(sdo_write(node, communication, 5, 20));  // event timer [ms]
  }
  out.push_back(sdo_write(node, communication, 1, cob_id));
}

}  // namespace

ProductionController::ProductionController(const OperationOptions& options, const sim::TrueRobot& model,
                                           sim::Preset preset, const NodeLayout& layout, int segments, sim::Rng rng,
                                           const std::array<double, kCableCount>& start_payout_m)
    : options_(options), model_(model), spec_(sim::preset_spec(preset)), layout_(layout), segments_(segments),
      rng_(rng), payout_m_(start_payout_m) {}

void ProductionController::commission(std::vector<drivers::can::CanFrame>& out) const {
  for (int i = 0; i < kCableCount; ++i) {
    const int drive = layout_.drive_node_id[i], encoder = layout_.encoder_node_id[i];
    configure_pdo(drive, 0x1800, 0x180 + static_cast<std::uint32_t>(drive), {0x60410010, 0x60640020}, true, out);
    configure_pdo(drive, 0x1400, 0x200 + static_cast<std::uint32_t>(drive), {0x60400010, 0x607A0020}, false, out);
    out.push_back(sdo_write(drive, 0x6060, 0, 1));  // profile position
    out.push_back(sdo_write(drive, 0x1017, 0, 100));
    configure_pdo(encoder, 0x1800, 0x180 + static_cast<std::uint32_t>(encoder), {0x60040020}, true, out);
    out.push_back(sdo_write(encoder, 0x1017, 0, 100));
    out.push_back(nmt_start(drive));
    out.push_back(nmt_start(encoder));
  }
  for (const std::uint16_t controlword : {0x0006, 0x0007, 0x000F}) {
    for (int i = 0; i < kCableCount; ++i) out.push_back(rpdo1(layout_.drive_node_id[i], controlword, 0));
  }
}

void ProductionController::step(double t_s, CanopenNodes& nodes, std::vector<drivers::can::CanFrame>& out) {
  switch (phase_) {
    case Phase::kCommission:
      commission(out);
      for (int i = 0; i < kCableCount; ++i) {
        target_counts_[i] = static_cast<std::int32_t>(std::lround(nodes.drive(i).position_counts()));
      }
      phase_ = Phase::kResting;
      until_s_ = t_s + rng_.uniform(options_.rest_min_s, options_.rest_max_s);
      return;
    case Phase::kResting:
      if (t_s < until_s_) return;
      if (!start_move(out)) {
        until_s_ = t_s + options_.rest_min_s;  // try again after another rest
        return;
      }
      phase_ = Phase::kStarting;
      until_s_ = t_s + kHandshakeS;
      return;
    case Phase::kStarting:
      if (t_s < until_s_) return;
      send_targets(kControlwordEnable, out);  // bit 4 low: the handshake ends
      phase_ = Phase::kMoving;
      until_s_ = t_s + kHandshakeS;
      return;
    case Phase::kMoving:
      if (t_s < until_s_ || !nodes.winches_still()) return;
      ++rests_;
      phase_ = Phase::kResting;
      until_s_ = t_s + rng_.uniform(options_.rest_min_s, options_.rest_max_s);
      return;
  }
}

bool ProductionController::start_move(std::vector<drivers::can::CanFrame>& out) {
  sim::SolverOptions solver;
  solver.segments = segments_;
  const Eigen::Vector3d size = spec_.workspace_max - spec_.workspace_min;
  for (int attempt = 0; attempt < kTries; ++attempt) {
    Eigen::Vector3d target;
    for (int k = 0; k < 3; ++k) {
      target(k) = spec_.workspace_min(k) + size(k) * rng_.uniform(options_.margin, 1.0 - options_.margin);
    }
    const sim::EquilibriumResult rest = sim::solve_equilibrium(model_, target, 0.0, solver);
    if (!rest) {
      ++unreachable_;
      continue;
    }
    std::array<double, kCableCount> next{};
    double longest_m = 0.0;
    for (int i = 0; i < kCableCount; ++i) {
      next[i] = rest->cables[i].payout_m + model_.encoder_offset_m[i];
      longest_m = std::max(longest_m, std::abs(next[i] - payout_m_[i]));
    }
    if (!(longest_m > 0.0)) continue;
    for (int i = 0; i < kCableCount; ++i) {
      // Every drive runs a scaled copy of the longest move's trapezoid: all arrive together.
      const double share = std::max(1e-3, std::abs(next[i] - payout_m_[i]) / longest_m);
      const auto counts = [&](double metres) {
        return static_cast<std::uint32_t>(std::max(1.0, std::round(share * metres / layout_.drive_m_per_count)));
      };
      const int node = layout_.drive_node_id[i];
      out.push_back(sdo_write(node, 0x6081, 0, counts(options_.winch_speed_mps)));
      out.push_back(sdo_write(node, 0x6083, 0, counts(options_.acceleration_mps2)));
      out.push_back(sdo_write(node, 0x6084, 0, counts(options_.acceleration_mps2)));
      target_counts_[i] = static_cast<std::int32_t>(std::lround(next[i] / layout_.drive_m_per_count));
    }
    payout_m_ = next;
    send_targets(kControlwordNewSetpoint, out);
    ++moves_;
    return true;
  }
  return false;
}

void ProductionController::send_targets(std::uint16_t controlword, std::vector<drivers::can::CanFrame>& out) const {
  for (int i = 0; i < kCableCount; ++i) out.push_back(rpdo1(layout_.drive_node_id[i], controlword, target_counts_[i]));
}

}  // namespace cdpr::virtual_robot
