#include "drivers/can/listening_winch_bank.h"

#include <cmath>
#include <cstdio>

#include "drivers/can/cia402.h"
#include "drivers/can/drain_frames.h"

namespace cdpr::drivers::can {
namespace {

std::uint32_t le32(const CanFrame& f, int at) {
  return static_cast<std::uint32_t>(f.data[at]) | static_cast<std::uint32_t>(f.data[at + 1]) << 8 |
         static_cast<std::uint32_t>(f.data[at + 2]) << 16 | static_cast<std::uint32_t>(f.data[at + 3]) << 24;
}

bool fits(int at, int bytes, const CanFrame& f) { return at >= 0 && at + bytes <= f.len; }

}  // namespace

std::string validate(const ListenLayout& l) {
  const auto byte = [](const char* name, int at, int bytes, bool optional) -> std::string {
    if ((optional && at == -1) || (at >= 0 && at + bytes <= 8)) return "";
    return std::string(name) + " " + std::to_string(at) + ": " + std::to_string(bytes) + " bytes do not fit a frame";
  };
  for (const std::uint32_t base : {l.drive_tpdo_base, l.encoder_tpdo_base}) {
    if (base + kMaxNodeId > kMaxStandardId) return "TPDO base " + std::to_string(base) + " + node id exceeds 0x7FF";
  }
  for (std::string problem : {byte("drive_statusword_byte", l.drive_statusword_byte, 2, true),
                              byte("drive_position_byte", l.drive_position_byte, 4, true),
                              byte("encoder_position_byte", l.encoder_position_byte, 4, false)}) {
    if (!problem.empty()) return problem;
  }
  return "";
}

ListeningWinchBank::ListeningWinchBank(CanWinchBankConfig config, ListenLayout layout, CanConnector connector)
    : config_(std::move(config)), layout_(layout), connector_(std::move(connector)) {
  for (const CanWinchConfig& c : config_.winches) {
    Winch w;
    w.drive.id = c.drive_node_id;
    w.encoder.id = c.encoder_node_id;
    w.unwrap.set_range(config_.encoder.measuring_range);
    winches_.push_back(std::move(w));
  }
}

hal::Status ListeningWinchBank::refused() {
  return hal::Status(hal::ErrorCode::kInvalidState, "watch mode: the robot's controller owns the drives");
}

hal::Status ListeningWinchBank::open() {
  for (const std::string& problem : {validate(config_), validate(layout_)}) {
    if (!problem.empty()) return hal::Status(hal::ErrorCode::kInvalidArgument, "CAN listener: " + problem);
  }
  auto transport = connector_();
  if (!transport.ok()) return transport.status();
  transport_ = std::move(transport.value());
  for (Winch& w : winches_) {
    w.unwrap.reset();
    w.position_time_us = -1;
    w.statusword_seen = false;
    for (Node* node : {&w.drive, &w.encoder}) node->last_heartbeat_us = node->last_pdo_us = -1;
  }
  return hal::Status::Ok();
}

hal::Status ListeningWinchBank::update(hal::TimeUs now_us) {
  if (!transport_) return hal::Status(hal::ErrorCode::kNotConnected, "CAN listener: not open");
  now_us_ = now_us;
  return drain_frames(*transport_, config_.max_frames_per_update, counters_,
                      [&](const CanFrame& frame) { dispatch(frame, now_us); });
}

void ListeningWinchBank::dispatch(const CanFrame& frame, hal::TimeUs now_us) {
  for (std::size_t i = 0; i < winches_.size(); ++i) {
    Winch& w = winches_[i];
    for (Node* node : {&w.drive, &w.encoder}) {
      if (node->id == 0 || frame.id != kHeartbeatBase + static_cast<std::uint32_t>(node->id)) continue;
      if (const std::optional<NmtState> state = parse_heartbeat(frame)) {
        node->nmt = *state;
        node->last_heartbeat_us = now_us;
        if (*state == NmtState::kBootUp) w.unwrap.reset();  // re-zeroed or replaced: no jump across it
      }
      return;
    }
    if (frame.id == layout_.drive_tpdo_base + static_cast<std::uint32_t>(w.drive.id)) {
      w.drive.last_pdo_us = now_us;
      if (fits(layout_.drive_statusword_byte, 2, frame)) {
        w.statusword = static_cast<std::uint16_t>(frame.data[layout_.drive_statusword_byte] |
                                                  frame.data[layout_.drive_statusword_byte + 1] << 8);
        w.statusword_seen = true;
      }
      if (w.encoder.id == 0 && fits(layout_.drive_position_byte, 4, frame)) {
        on_position(i, le32(frame, layout_.drive_position_byte), now_us);
      }
      return;
    }
    if (w.encoder.id != 0 && frame.id == layout_.encoder_tpdo_base + static_cast<std::uint32_t>(w.encoder.id)) {
      w.encoder.last_pdo_us = now_us;
      if (fits(layout_.encoder_position_byte, 4, frame)) on_position(i, le32(frame, layout_.encoder_position_byte), now_us);
      return;
    }
  }
  ++counters_.frames_ignored;
}

void ListeningWinchBank::on_position(std::size_t i, std::uint32_t raw, hal::TimeUs now_us) {
  Winch& w = winches_[i];
  const CanWinchConfig& c = config_.winches[i];
  const double m_per_count = std::abs(c.encoder_node_id == 0 ? c.drive_m_per_count : c.encoder_m_per_count);
  // The drive's INTEGER32 position is unwrapped like an encoder's over 2^32.
  switch (w.unwrap.add(raw, EncoderUnwrap::max_change_counts(config_.max_speed_mps, w.position_time_us, now_us,
                                                             config_.heartbeat_timeout_us, m_per_count))) {
    case EncoderUnwrap::Outcome::kOk: w.position_time_us = now_us; return;
    case EncoderUnwrap::Outcome::kOutOfRange:
      ++counters_.errors;
      if (w.fault.empty()) w.fault = "position " + std::to_string(raw) + " outside the measuring range";
      return;
    case EncoderUnwrap::Outcome::kJump:
      if (w.fault.empty()) {
        w.fault = "position jumped by " + std::to_string(w.unwrap.last_jump_counts()) +
                  " counts between two readings, more than max_speed_mps allows";
      }
      return;
  }
}

bool ListeningWinchBank::alive(const Node& node) const {
  const auto fresh = [&](hal::TimeUs at) { return at >= 0 && now_us_ - at <= config_.heartbeat_timeout_us; };
  return fresh(node.last_heartbeat_us) && node.nmt == NmtState::kOperational && fresh(node.last_pdo_us);
}

hal::WinchStatus ListeningWinchBank::status(int winch) const {
  const Winch& w = winches_[static_cast<std::size_t>(winch)];
  const CanWinchConfig& c = config_.winches[static_cast<std::size_t>(winch)];
  hal::WinchStatus s;
  const double m_per_count = c.encoder_node_id == 0 ? c.drive_m_per_count : c.encoder_m_per_count;
  s.position_valid = w.unwrap.valid() && w.fault.empty();
  s.payout_m = static_cast<double>(w.unwrap.counts()) * m_per_count;
  s.position_time_us = w.position_time_us;
  s.alive = alive(w.drive) && (w.encoder.id == 0 || alive(w.encoder));
  hal::TimeUs oldest = w.drive.last_heartbeat_us;
  if (w.encoder.id != 0 && (oldest < 0 || w.encoder.last_heartbeat_us < oldest)) oldest = w.encoder.last_heartbeat_us;
  s.heartbeat_age_us = oldest < 0 ? -1 : now_us_ - oldest;
  if (w.statusword_seen) {
    switch (cia402::decode_power_state(w.statusword)) {
      case cia402::PowerState::kOperationEnabled: s.drive = hal::DriveState::kEnabled; break;
      case cia402::PowerState::kQuickStopActive: s.drive = hal::DriveState::kQuickStop; break;
      case cia402::PowerState::kFault:
      case cia402::PowerState::kFaultReactionActive: s.drive = hal::DriveState::kFault; break;
      default: s.drive = hal::DriveState::kDisabled; break;
    }
    s.target_reached = (w.statusword & cia402::kSwTargetReached) != 0;
  }
  s.fault = !w.fault.empty();
  return s;
}

int ListeningWinchBank::node_count(int winch) const {
  return winches_[static_cast<std::size_t>(winch)].encoder.id != 0 ? 2 : 1;
}

hal::NodeStatus ListeningWinchBank::node_status(int winch, int node) const {
  const Winch& w = winches_[static_cast<std::size_t>(winch)];
  const Node& n = node == 0 ? w.drive : w.encoder;
  hal::NodeStatus s;
  s.role = node == 0 ? "drive" : "encoder";
  s.node_id = n.id;
  const bool heard = n.last_heartbeat_us >= 0 && now_us_ - n.last_heartbeat_us <= config_.heartbeat_timeout_us;
  s.nmt = n.last_heartbeat_us < 0 ? "unknown" : heard ? to_string(n.nmt) : "silent";
  s.configured = false;  // the controller's configuration: not the daemon's to verify
  if (node == 0 && w.statusword_seen) s.power_state = to_string(cia402::decode_power_state(w.statusword));
  s.pdo_age_us = n.last_pdo_us < 0 ? -1 : now_us_ - n.last_pdo_us;
  s.heartbeat_age_us = n.last_heartbeat_us < 0 ? -1 : now_us_ - n.last_heartbeat_us;
  return s;
}

hal::Status ListeningWinchBank::reset_faults() {
  for (Winch& w : winches_) {
    if (w.fault.empty()) continue;
    w.fault.clear();
    w.unwrap.reset();
  }
  return hal::Status::Ok();
}

}  // namespace cdpr::drivers::can
