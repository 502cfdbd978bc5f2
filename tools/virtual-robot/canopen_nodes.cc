#include "virtual-robot/canopen_nodes.h"

#include <cmath>

namespace cdpr::virtual_robot {

namespace can = drivers::can;
namespace cia402 = drivers::can::cia402;

CanopenNodes::CanopenNodes(const NodeLayout& layout, RobotPhysics& physics, sim::Rng rng, hal::TimeUs now_us)
    : layout_(layout), physics_(physics), rng_(rng), next_pdo_us_(now_us) {
  for (int i = 0; i < kCableCount; ++i) {
    drives_[i].node.id = layout.drive_node_id[i];
    drives_[i].encoder.id = layout.encoder_node_id[i];
    drives_[i].node.next_heartbeat_us = now_us;
    drives_[i].encoder.next_heartbeat_us = now_us;
  }
}

void CanopenNodes::silence(int node_id, bool silent) {
  for (Drive& d : drives_) {
    if (d.node.id == node_id) d.node.silent = silent;
    if (d.encoder.id == node_id) d.encoder.silent = silent;
  }
}

void CanopenNodes::on_frame(const can::CanFrame& frame) {
  if (frame.id == can::kNmtCobId) {
    if (const auto command = can::parse_nmt(frame)) on_nmt(*command);
    return;
  }
  const auto node = can::node_of(frame, can::kRpdo1Base);
  if (!node) return;
  for (int i = 0; i < kCableCount; ++i) {
    if (drives_[i].node.id != *node || drives_[i].node.silent) continue;
    if (drives_[i].node.nmt != can::NmtState::kOperational) return;  // PDOs only when operational
    if (const auto pdo = can::parse_drive_rxpdo(frame)) on_rxpdo(i, *pdo);
  }
}

void CanopenNodes::on_nmt(const can::NmtCommandFrame& command) {
  for (Drive& d : drives_) {
    for (Node* node : {&d.node, &d.encoder}) {
      if (node->silent || (command.node_id != 0 && command.node_id != node->id)) continue;
      switch (command.command) {
        case can::NmtCommand::kStart: node->nmt = can::NmtState::kOperational; break;
        case can::NmtCommand::kStop: node->nmt = can::NmtState::kStopped; break;
        case can::NmtCommand::kEnterPreOperational: node->nmt = can::NmtState::kPreOperational; break;
        case can::NmtCommand::kResetNode:
        case can::NmtCommand::kResetCommunication:
          node->nmt = can::NmtState::kPreOperational;
          node->boot_up_pending = true;
          break;
      }
    }
  }
}

void CanopenNodes::on_rxpdo(int winch, const can::DriveRxPdo& pdo) {
  Drive& d = drives_[winch];
  const std::uint16_t previous = d.controlword;
  d.controlword = pdo.controlword;
  d.power = cia402::next_power_state(d.power, pdo.controlword, previous);
  const bool enabled = d.power == cia402::PowerState::kOperationEnabled;
  const bool new_setpoint = (pdo.controlword & cia402::kCwNewSetpoint) != 0;
  if (enabled && new_setpoint && (previous & cia402::kCwNewSetpoint) == 0) {
    physics_.set_target(winch, layout_.drive_m_per_count * static_cast<double>(pdo.target_counts));
    d.setpoint_ack = true;
  }
  if (!new_setpoint) d.setpoint_ack = false;
  if (!enabled || (pdo.controlword & cia402::kCwHalt) != 0) physics_.stop(winch);
}

std::uint16_t CanopenNodes::statusword(int winch) const {
  const Drive& d = drives_[winch];
  std::uint16_t sw = cia402::statusword_of(d.power);
  const bool enabled = d.power == cia402::PowerState::kOperationEnabled;
  if (enabled && physics_.at_target(winch)) sw |= cia402::kSwTargetReached;
  if (d.setpoint_ack) sw |= cia402::kSwSetpointAcknowledge;
  return sw;
}

void CanopenNodes::heartbeat(Node& node, hal::TimeUs now_us, std::vector<can::CanFrame>& out) {
  if (node.silent) return;
  if (node.boot_up_pending) {
    out.push_back(can::make_heartbeat(node.id, can::NmtState::kBootUp));
    node.boot_up_pending = false;
  }
  if (now_us < node.next_heartbeat_us) return;
  node.next_heartbeat_us = now_us + layout_.heartbeat_period_us;
  out.push_back(can::make_heartbeat(node.id, node.nmt));
}

void CanopenNodes::poll(hal::TimeUs now_us, std::vector<can::CanFrame>& out) {
  for (Drive& d : drives_) {
    heartbeat(d.node, now_us, out);
    heartbeat(d.encoder, now_us, out);
  }
  if (now_us < next_pdo_us_) return;
  next_pdo_us_ = now_us + layout_.pdo_period_us;
  for (int i = 0; i < kCableCount; ++i) {
    const Drive& d = drives_[i];
    const double payout_m = physics_.payout_m(i);
    if (!d.node.silent && d.node.nmt == can::NmtState::kOperational) {
      const auto counts = static_cast<std::int32_t>(std::lround(payout_m / layout_.drive_m_per_count));
      out.push_back(can::make_drive_txpdo(d.node.id, statusword(i), counts));
    }
    if (!d.encoder.silent && d.encoder.nmt == can::NmtState::kOperational) {
      const double reading_m = payout_m + layout_.encoder_noise_m * rng_.normal();
      out.push_back(can::make_encoder_tpdo(
          d.encoder.id, static_cast<std::int32_t>(std::lround(reading_m / layout_.encoder_m_per_count))));
    }
  }
}

}  // namespace cdpr::virtual_robot
