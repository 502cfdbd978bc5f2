#include "drivers/can/canopen_winch_bank.h"

#include <algorithm>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <utility>

#include "drivers/can/fd_can_transport.h"

namespace cdpr::drivers::can {
namespace {

bool valid_node_id(int id) { return id >= 1 && id <= kMaxNodeId; }

}  // namespace

CanConnector make_can_connector(const std::string& endpoint) {
  // Both transports are FdCanTransport; only the way to open the fd differs.
  using Open = hal::Result<std::unique_ptr<FdCanTransport>> (*)(const std::string&);
  const auto connector = [](Open open, std::string where) -> CanConnector {
    return [open, where]() -> hal::Result<std::unique_ptr<CanTransport>> {
      auto transport = open(where);
      if (!transport.ok()) return transport.status();
      return std::unique_ptr<CanTransport>(std::move(transport.value()));
    };
  };
  if (endpoint.starts_with("socketcan:")) return connector(&FdCanTransport::open_socketcan, endpoint.substr(10));
  if (endpoint.starts_with("unix:")) return connector(&FdCanTransport::connect_unix, endpoint.substr(5));
  return [endpoint]() -> hal::Result<std::unique_ptr<CanTransport>> {
    return hal::Status(hal::ErrorCode::kInvalidArgument,
                       "CAN endpoint '" + endpoint + "': expected socketcan:<interface> or unix:<path>");
  };
}

std::string validate(const CanWinchBankConfig& config) {
  if (config.winches.empty()) return "no winches configured";
  for (std::size_t i = 0; i < config.winches.size(); ++i) {
    const CanWinchConfig& w = config.winches[i];
    const std::string where = "winch " + std::to_string(i) + ": ";
    if (!valid_node_id(w.drive_node_id)) return where + "drive node id " + std::to_string(w.drive_node_id) + " out of 1..127";
    if (w.encoder_node_id != 0 && !valid_node_id(w.encoder_node_id)) {
      return where + "encoder node id " + std::to_string(w.encoder_node_id) + " out of 0..127";
    }
    if (w.encoder_node_id == w.drive_node_id) return where + "encoder and drive share a node id";
    if (!std::isfinite(w.encoder_m_per_count) || w.encoder_m_per_count == 0.0) return where + "bad encoder_m_per_count";
    if (!std::isfinite(w.drive_m_per_count) || w.drive_m_per_count == 0.0) return where + "bad drive_m_per_count";
    for (std::size_t j = 0; j < i; ++j) {
      const CanWinchConfig& o = config.winches[j];
      for (int id : {w.drive_node_id, w.encoder_node_id}) {
        if (id != 0 && (id == o.drive_node_id || id == o.encoder_node_id)) {
          return where + "node id " + std::to_string(id) + " also used by winch " + std::to_string(j);
        }
      }
    }
  }
  if (config.heartbeat_timeout_us <= 0 || config.resend_interval_us <= 0 || config.max_frames_per_update <= 0) {
    return "heartbeat timeout, resend interval and frames per update must be positive";
  }
  return {};
}

CanopenWinchBank::CanopenWinchBank(CanWinchBankConfig config, CanConnector connector)
    : config_(std::move(config)), connector_(std::move(connector)) {
  winches_.reserve(config_.winches.size());
  for (const CanWinchConfig& c : config_.winches) {
    Winch w{Node{}, Node{}, Cia402Drive(config_.resend_interval_us)};
    w.drive_node.id = c.drive_node_id;
    w.encoder_node.id = c.encoder_node_id;
    winches_.push_back(std::move(w));
  }
}

hal::Status CanopenWinchBank::check_open() const {
  if (!transport_) return hal::Status(hal::ErrorCode::kInvalidState, "CAN winch bank: not open");
  return hal::Status::Ok();
}

hal::Status CanopenWinchBank::open() {
  if (std::string problem = validate(config_); !problem.empty()) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "CAN winch bank: " + problem);
  }
  auto transport = connector_();
  if (!transport.ok()) return transport.status();
  transport_ = std::move(transport.value());
  for (Winch& w : winches_) {
    w.drive.reset();
    w.encoder_valid = false;
    for (Node* node : {&w.drive_node, &w.encoder_node}) {
      node->last_heartbeat_us = -1;
      node->start_wanted = node->id != 0;
      node->last_start_sent_us = -1;
    }
  }
  // Start the nodes now (retried from update() until their heartbeat says
  // operational).
  for (Winch& w : winches_) {
    for (Node* node : {&w.drive_node, &w.encoder_node}) {
      if (node->id == 0) continue;
      if (hal::Status s = service_node(*node, now_us_); !s.ok()) return s;
    }
  }
  return hal::Status::Ok();
}

void CanopenWinchBank::close() { transport_.reset(); }

hal::Status CanopenWinchBank::send(const CanFrame& frame) {
  if (hal::Status s = check_open(); !s.ok()) return s;
  hal::Status s = transport_->send(frame);
  if (s.ok()) {
    ++counters_.frames_tx;
  } else {
    ++counters_.errors;
  }
  return s;
}

hal::Status CanopenWinchBank::update(hal::TimeUs now_us) {
  if (hal::Status s = check_open(); !s.ok()) return s;
  now_us_ = now_us;
  CanFrame frame;
  for (int i = 0; i < config_.max_frames_per_update; ++i) {
    hal::Result<bool> got = transport_->receive(frame, 0);
    if (!got.ok()) {
      ++counters_.errors;
      if (got.status().code() == hal::ErrorCode::kCorruptData) continue;  // one bad record: skip it
      return got.status();
    }
    if (!got.value()) break;
    ++counters_.frames_rx;
    dispatch(frame, now_us);
  }
  hal::Status first_error;
  for (Winch& w : winches_) {
    for (Node* node : {&w.drive_node, &w.encoder_node}) {
      if (node->id == 0) continue;
      if (hal::Status s = service_node(*node, now_us); !s.ok() && first_error.ok()) first_error = s;
    }
  }
  if (hal::Status s = poll_drives(now_us); !s.ok() && first_error.ok()) first_error = s;
  return first_error;
}

void CanopenWinchBank::dispatch(const CanFrame& frame, hal::TimeUs now_us) {
  for (Winch& w : winches_) {
    if (auto node = node_of(frame, kHeartbeatBase)) {
      Node* target = *node == w.drive_node.id ? &w.drive_node : *node == w.encoder_node.id ? &w.encoder_node : nullptr;
      if (target == nullptr) continue;
      if (auto state = parse_heartbeat(frame)) {
        on_heartbeat(w, *target, *state, now_us);
      } else {
        ++counters_.errors;
      }
      return;
    }
    if (auto node = node_of(frame, kTpdo1Base)) {
      if (*node == w.drive_node.id) {
        if (auto pdo = parse_drive_txpdo(frame)) {
          w.drive.on_status(*pdo);
          if (w.encoder_node.id == 0) {
            w.encoder_counts = pdo->actual_counts;
            w.encoder_valid = true;
            w.encoder_time_us = now_us;
          }
        } else {
          ++counters_.errors;
        }
        return;
      }
      if (*node == w.encoder_node.id) {
        if (auto counts = parse_encoder_tpdo(frame)) {
          w.encoder_counts = *counts;
          w.encoder_valid = true;
          w.encoder_time_us = now_us;
        } else {
          ++counters_.errors;
        }
        return;
      }
    }
  }
  ++counters_.frames_ignored;  // our own RxPDOs echoed, other nodes, SYNC, EMCY, ...
}

void CanopenWinchBank::on_heartbeat(Winch& winch, Node& node, NmtState state, hal::TimeUs now_us) {
  node.last_heartbeat_us = now_us;
  if (state == NmtState::kBootUp && &node == &winch.drive_node) {
    // Rebooted: forget what it said, and do not re-enable it behind the
    // daemon's back: it stays disabled until enable() is called again.
    winch.drive.reset();
    winch.drive.set_goal(Cia402Drive::Goal::kNone);
  }
  node.nmt_state = state;
  node.start_wanted = state != NmtState::kOperational;
}

hal::Status CanopenWinchBank::service_node(Node& node, hal::TimeUs now_us) {
  if (!node.start_wanted) return hal::Status::Ok();
  if (node.last_start_sent_us >= 0 && now_us - node.last_start_sent_us < config_.resend_interval_us) {
    return hal::Status::Ok();
  }
  node.last_start_sent_us = now_us;
  return send(make_nmt(NmtCommand::kStart, node.id));
}

hal::Status CanopenWinchBank::poll_drives(hal::TimeUs now_us) {
  hal::Status first_error;
  for (Winch& w : winches_) {
    if (auto pdo = w.drive.poll(now_us)) {
      hal::Status s = send(make_drive_rxpdo(w.drive_node.id, pdo->controlword, pdo->target_counts));
      if (!s.ok() && first_error.ok()) first_error = s;
    }
  }
  return first_error;
}

bool CanopenWinchBank::node_alive(const Node& node) const {
  return node.id == 0 || (node.last_heartbeat_us >= 0 && now_us_ - node.last_heartbeat_us <= config_.heartbeat_timeout_us);
}

double CanopenWinchBank::payout_m(const Winch& w) const {
  const std::size_t i = static_cast<std::size_t>(&w - winches_.data());
  const CanWinchConfig& c = config_.winches[i];
  const double m_per_count = c.encoder_node_id == 0 ? c.drive_m_per_count : c.encoder_m_per_count;
  return static_cast<double>(w.encoder_counts) * m_per_count;
}

hal::WinchStatus CanopenWinchBank::status(int winch) const {
  if (winch < 0 || winch >= winch_count()) std::abort();  // caller's broken invariant (hal/winch_bank.h)
  const Winch& w = winches_[static_cast<std::size_t>(winch)];
  hal::WinchStatus s;
  s.payout_m = payout_m(w);
  s.position_valid = w.encoder_valid;
  s.position_time_us = w.encoder_time_us;
  s.target_payout_m = w.target_payout_m;
  hal::TimeUs oldest_us = std::numeric_limits<hal::TimeUs>::max();
  bool heard_all = true;
  for (const Node* node : {&w.drive_node, &w.encoder_node}) {
    if (node->id == 0) continue;
    heard_all = heard_all && node->last_heartbeat_us >= 0;
    oldest_us = std::min(oldest_us, node->last_heartbeat_us);
  }
  s.heartbeat_age_us = heard_all ? now_us_ - oldest_us : -1;
  s.alive = transport_ != nullptr && heard_all && node_alive(w.drive_node) && node_alive(w.encoder_node);
  s.drive = w.drive.drive_state();
  s.target_reached = w.drive.target_reached();
  return s;
}

hal::Status CanopenWinchBank::set_goal_all(Cia402Drive::Goal goal) {
  if (hal::Status s = check_open(); !s.ok()) return s;
  for (Winch& w : winches_) w.drive.set_goal(goal);
  return poll_drives(now_us_);
}

hal::Status CanopenWinchBank::enable() { return set_goal_all(Cia402Drive::Goal::kEnabled); }
hal::Status CanopenWinchBank::disable() { return set_goal_all(Cia402Drive::Goal::kDisabled); }
hal::Status CanopenWinchBank::quick_stop() { return set_goal_all(Cia402Drive::Goal::kQuickStop); }

hal::Status CanopenWinchBank::halt() {
  if (hal::Status s = check_open(); !s.ok()) return s;
  for (Winch& w : winches_) w.drive.set_halt(true);
  return poll_drives(now_us_);
}

hal::Status CanopenWinchBank::set_target_payout(int winch, double payout_target_m) {
  if (winch < 0 || winch >= winch_count() || !std::isfinite(payout_target_m)) {
    return hal::Status(hal::ErrorCode::kInvalidArgument,
                       "CAN winch bank: bad winch index " + std::to_string(winch) + " or non-finite target");
  }
  if (hal::Status s = check_open(); !s.ok()) return s;
  Winch& w = winches_[static_cast<std::size_t>(winch)];
  const hal::WinchStatus now = status(winch);
  if (!now.alive || now.drive != hal::DriveState::kEnabled || !now.position_valid) {
    return hal::Status(hal::ErrorCode::kInvalidState,
                       "winch " + std::to_string(winch) + " (node " + std::to_string(w.drive_node.id) + "): " +
                           (now.alive ? std::string("drive ") + hal::to_string(now.drive) : std::string("node dead")) +
                           ", target refused");
  }
  const double m_per_count = config_.winches[static_cast<std::size_t>(winch)].drive_m_per_count;
  const double target = static_cast<double>(w.drive.actual_counts()) +
                        std::round((payout_target_m - now.payout_m) / m_per_count);
  if (target < std::numeric_limits<std::int32_t>::min() || target > std::numeric_limits<std::int32_t>::max()) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "winch " + std::to_string(winch) + ": target out of drive range");
  }
  w.target_payout_m = payout_target_m;
  w.drive.command_target(static_cast<std::int32_t>(target));
  return poll_drives(now_us_);
}

bool CanopenWinchBank::motion_finished() const {
  for (int i = 0; i < winch_count(); ++i) {
    const hal::WinchStatus s = status(i);
    if (!s.alive || s.drive != hal::DriveState::kEnabled || !s.target_reached) return false;
  }
  return true;
}

}  // namespace cdpr::drivers::can
