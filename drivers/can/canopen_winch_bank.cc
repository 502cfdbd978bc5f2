#include "drivers/can/canopen_winch_bank.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>

#include "drivers/can/drain_frames.h"
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
  if (!(config.max_move_m > 0.0) || !(config.max_speed_mps > 0.0)) return "max_move and max_speed must be positive";
  if (!(config.min_payout_m < config.max_payout_m) || !(config.position_limit_margin_m >= 0.0)) {
    return "payout range: min must be below max, and the position limit margin not negative";
  }
  if (!valid_node_id(config.master_node_id)) return "master node id out of 1..127";
  for (const CanWinchConfig& w : config.winches) {
    if (w.drive_node_id == config.master_node_id || w.encoder_node_id == config.master_node_id) {
      return "master node id " + std::to_string(config.master_node_id) + " also used by a winch node";
    }
  }
  if (config.master_heartbeat_us <= 0 || config.sdo_timeout_us <= 0) return "master heartbeat and SDO timeout must be positive";
  if (config.drive.consumer_heartbeat_us <= config.master_heartbeat_us) {
    return "the drives' consumer heartbeat time must exceed the master's heartbeat period";
  }
  if (std::string problem = validate(config.drive); !problem.empty()) return "drive: " + problem;
  if (std::string problem = validate(config.encoder); !problem.empty()) return "encoder: " + problem;
  return {};
}

CanopenWinchBank::CanopenWinchBank(CanWinchBankConfig config, CanConnector connector)
    : config_(std::move(config)), connector_(std::move(connector)) {
  // The mode check's write goes out once; its expected display value is
  // read (not compared once) until the drive shows it.
  for (const SdoStep& step : drive_mode_check()) {
    if (step.kind != SdoStep::Kind::kExpect) {
      mode_write_steps_.push_back(step);
    } else {
      mode_display_steps_.push_back({SdoStep::Kind::kRead, step.index, step.subindex, step.size, 0, step.what});
      mode_wanted_ = step.value;
    }
  }
  winches_.reserve(config_.winches.size());
  for (const CanWinchConfig& c : config_.winches) {
    Winch w{Node(c.drive_node_id, config_.sdo_timeout_us),
            Node(c.encoder_node_id, config_.sdo_timeout_us),
            Cia402Drive(config_.resend_interval_us),
            DriveUnits{},
            EncoderUnwrap(),
            -1,
            0.0,
            EnableStep::kNone,
            false,
            {},
            false,
            0,
            {},
            {},
            {},
            false,
            {},
            0,
            0,
            0,
            {}};
    w.drive_node.probe_steps = drive_probe(config_.drive);
    if (c.encoder_node_id != 0) w.encoder_node.steps = encoder_configuration(c.encoder_node_id, config_.encoder);
    w.error_code_steps = {{SdoStep::Kind::kRead, 0x603F, 0, 2, 0, "error code"}};
    w.profile_steps = {{SdoStep::Kind::kWrite, 0x6081, 0, 4, 0, "profile velocity"},
                       {SdoStep::Kind::kWrite, 0x6083, 0, 4, 0, "profile acceleration"},
                       {SdoStep::Kind::kWrite, 0x6084, 0, 4, 0, "profile deceleration"},
                       {SdoStep::Kind::kWrite, 0x6085, 0, 4, 0, "quick stop deceleration"}};
    winches_.push_back(std::move(w));
  }
  for (Winch& w : winches_) w.encoder.set_centre(payout_centre_counts(w));
  if (!config_.last_positions_path.empty()) {
    kept_counts_ = read_last_positions(config_.last_positions_path, winches_.size());
    for (std::size_t i = 0; i < winches_.size(); ++i) {
      if (kept_counts_[i]) winches_[i].encoder.set_centre(*kept_counts_[i]);
    }
  }
  fit_to_devices();
}

hal::Status CanopenWinchBank::check_open() const {
  if (!transport_) return hal::Status(hal::ErrorCode::kInvalidState, "CAN winch bank: not open");
  return hal::Status::Ok();
}

hal::Status CanopenWinchBank::open() {
  if (std::string problem = validate(config_); !problem.empty()) {
    return hal::Status(hal::ErrorCode::kInvalidArgument, "CAN winch bank: " + problem);
  }
  if (!setup_error_.empty()) return hal::Status(hal::ErrorCode::kInvalidArgument, "CAN winch bank: " + setup_error_);
  auto transport = connector_();
  if (!transport.ok()) return transport.status();
  transport_ = std::move(transport.value());
  last_master_heartbeat_us_ = -1;
  for (Winch& w : winches_) {
    w.drive.reset();
    w.drive.set_goal(Cia402Drive::Goal::kNone);
    w.encoder.reset();
    w.encoder_time_us = -1;
    w.enable = EnableStep::kNone;
    w.fault.clear();
    for (Node* node : {&w.drive_node, &w.encoder_node}) {
      node->last_heartbeat_us = -1;
      node->last_pdo_us = -1;
      node->configured = false;
      node->configurator.cancel();
      node->configure_at_us = node->id != 0 ? now_us_ : -1;
      node->last_start_sent_us = -1;
      node->emcy_code = 0;
      node->emcy_register = 0;
    }
  }
  // Configuration starts from update(), one SDO frame per node per call.
  return send_master_heartbeat(now_us_);
}

void CanopenWinchBank::close() {
  if (transport_) keep_positions(true);
  transport_.reset();
}

void CanopenWinchBank::keep_positions(bool always) {
  if (config_.last_positions_path.empty()) return;
  kept_counts_.resize(winches_.size());
  bool moved = false;
  std::vector<std::optional<std::int64_t>> counts = kept_counts_;
  for (std::size_t i = 0; i < winches_.size(); ++i) {
    const Winch& w = winches_[i];
    if (w.encoder_node.id == 0 || !w.encoder.valid()) continue;
    counts[i] = w.encoder.counts();
    const auto eighth = static_cast<std::int64_t>(w.encoder.range() / 8);
    moved = moved || !kept_counts_[i] || std::llabs(*counts[i] - *kept_counts_[i]) > eighth || (always && counts[i] != kept_counts_[i]);
  }
  if (!moved) return;
  std::string error;
  if (!write_last_positions(config_.last_positions_path, counts, error)) {
    ++counters_.errors;  // kept again at the next eighth; the payout range's centre stays the fallback
    return;
  }
  kept_counts_ = counts;
  for (std::size_t i = 0; i < winches_.size(); ++i) {
    if (kept_counts_[i]) winches_[i].encoder.set_centre(*kept_counts_[i]);
  }
}

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
  if (hal::Status s = drain_frames(*transport_, config_.max_frames_per_update, counters_,
                                   [&](const CanFrame& frame) { dispatch(frame, now_us); });
      !s.ok()) {
    return s;
  }
  hal::Status first_error = send_master_heartbeat(now_us);
  for (Winch& w : winches_) {
    for (Node* node : {&w.drive_node, &w.encoder_node}) {
      if (node->id == 0) continue;
      if (hal::Status s = service_node(w, *node, now_us); !s.ok() && first_error.ok()) first_error = s;
    }
    if (hal::Status s = service_enable(w, now_us); !s.ok() && first_error.ok()) first_error = s;
    if (hal::Status s = service_error_code(w, now_us); !s.ok() && first_error.ok()) first_error = s;
  }
  if (hal::Status s = service_coordinated_move(now_us); !s.ok() && first_error.ok()) first_error = s;
  if (hal::Status s = poll_drives(now_us); !s.ok() && first_error.ok()) first_error = s;
  keep_positions(false);
  return first_error;
}

hal::Status CanopenWinchBank::send_master_heartbeat(hal::TimeUs now_us) {
  if (last_master_heartbeat_us_ >= 0 && now_us - last_master_heartbeat_us_ < config_.master_heartbeat_us) {
    return hal::Status::Ok();
  }
  last_master_heartbeat_us_ = now_us;
  return send(make_heartbeat(config_.master_node_id, NmtState::kOperational));
}

void CanopenWinchBank::dispatch(const CanFrame& frame, hal::TimeUs now_us) {
  for (Winch& w : winches_) {
    for (Node* node : {&w.drive_node, &w.encoder_node}) {
      if (node->id == 0) continue;
      const auto id = static_cast<std::uint32_t>(node->id);
      if (frame.id == kSdoResponseBase + id) {
        (void)node->configurator.on_frame(frame, now_us);
        return;
      }
      if (frame.id == kEmergencyBase + id) {
        on_emergency(w, *node, frame);
        return;
      }
      if (frame.id == kHeartbeatBase + id) {
        if (auto state = parse_heartbeat(frame)) {
          on_heartbeat(w, *node, *state, now_us);
        } else {
          ++counters_.errors;
        }
        return;
      }
      if (frame.id != kTpdo1Base + id) continue;
      // PDOs flow only in operational (CiA 301): the NMT start took effect
      // even if the heartbeat saying so is still to come.
      node->nmt_state = NmtState::kOperational;
      if (node == &w.drive_node) {
        if (auto pdo = parse_drive_txpdo(frame)) {
          node->last_pdo_us = now_us;
          w.drive.on_status(*pdo);
          if (w.encoder_node.id == 0) on_position(w, static_cast<std::uint32_t>(pdo->actual_counts), now_us);
        } else {
          ++counters_.errors;
        }
      } else if (auto counts = parse_encoder_tpdo(frame)) {
        node->last_pdo_us = now_us;
        on_position(w, *counts, now_us);
      } else {
        ++counters_.errors;
      }
      return;
    }
  }
  ++counters_.frames_ignored;  // our own frames echoed, other nodes, SYNC, ...
}

void CanopenWinchBank::on_emergency(Winch& w, Node& node, const CanFrame& frame) {
  if (frame.len < 3) {
    ++counters_.errors;
    return;
  }
  const auto code = static_cast<std::uint16_t>(frame.data[0] | frame.data[1] << 8);
  if (code == 0) return;  // error reset: the cause stays in the message until the next EMCY
  node.emcy_code = code;
  node.emcy_register = frame.data[2];
  char text[96];
  std::snprintf(text, sizeof(text), "EMCY 0x%04X (%s), error register 0x%02X from node %d", code,
                emergency_text(code), frame.data[2], node.id);
  w.emergency = text;
}

void CanopenWinchBank::on_position(Winch& w, std::uint32_t raw, hal::TimeUs now_us) {
  const std::size_t i = static_cast<std::size_t>(&w - winches_.data());
  const CanWinchConfig& c = config_.winches[i];
  const double m_per_count = std::abs(c.encoder_node_id == 0 ? c.drive_m_per_count : c.encoder_m_per_count);
  switch (w.encoder.add(raw, EncoderUnwrap::max_change_counts(config_.max_speed_mps, w.encoder_time_us, now_us,
                                                              config_.heartbeat_timeout_us, m_per_count))) {
    case EncoderUnwrap::Outcome::kOk:
      w.encoder_time_us = now_us;
      return;
    case EncoderUnwrap::Outcome::kOutOfRange:
      ++counters_.errors;
      if (w.fault.empty()) {
        w.fault = "node " + std::to_string(c.encoder_node_id != 0 ? c.encoder_node_id : c.drive_node_id) + ": position " + std::to_string(raw) + " outside the measuring range of " +
                  std::to_string(w.encoder.range()) + " counts";
      }
      return;
    case EncoderUnwrap::Outcome::kJump:
      if (w.fault.empty()) {
        w.fault = "node " + std::to_string(c.encoder_node_id != 0 ? c.encoder_node_id : c.drive_node_id) + ": position jumped by " + std::to_string(w.encoder.last_jump_counts()) + " counts (" +
                  std::to_string(static_cast<double>(w.encoder.last_jump_counts()) * m_per_count) +
                  " m) between two readings, more than " + std::to_string(config_.max_speed_mps) + " m/s allows";
      }
      return;
  }
}

void CanopenWinchBank::on_heartbeat(Winch& winch, Node& node, NmtState state, hal::TimeUs now_us) {
  node.last_heartbeat_us = now_us;
  node.nmt_state = state;
  if (state != NmtState::kBootUp) return;
  // Rebooted: its dictionary is back at the defaults, so configure it
  // again; and do not re-enable it behind the daemon's back: it stays
  // disabled until enable() is called again.
  node.configured = false;
  node.configurator.cancel();
  node.configure_at_us = now_us;
  node.last_pdo_us = -1;
  if (&node == &winch.drive_node) {
    winch.drive.reset();
    winch.drive.set_goal(Cia402Drive::Goal::kNone);
    winch.enable = EnableStep::kNone;
  } else {
    winch.encoder.reset();
  }
}

hal::Status CanopenWinchBank::service_node(Winch& w, Node& node, hal::TimeUs now_us) {
  if (node.configured) {
    // Configured: keep it operational (NMT start, rate-limited).
    if (node.nmt_state == NmtState::kOperational || node.last_heartbeat_us < 0) return hal::Status::Ok();
    if (node.last_start_sent_us >= 0 && now_us - node.last_start_sent_us < config_.resend_interval_us) {
      return hal::Status::Ok();
    }
    node.last_start_sent_us = now_us;
    return send(make_nmt(NmtCommand::kStart, node.id));
  }
  NodeConfigurator& c = node.configurator;
  if (c.state() != NodeConfigurator::State::kRunning) {
    if (node.configure_at_us < 0 || now_us < node.configure_at_us) return hal::Status::Ok();
    node.configure_at_us = -1;
    // PDO parameters change only in pre-operational.
    if (hal::Status s = send(make_nmt(NmtCommand::kEnterPreOperational, node.id)); !s.ok()) return s;
    node.probed = node.probe_steps.empty();
    c.start(node.probed ? &node.steps : &node.probe_steps);
  }
  std::optional<CanFrame> frame = c.poll(now_us);
  switch (c.state()) {
    case NodeConfigurator::State::kDone:
      if (!node.probed) {
        node.probed = true;
        if (std::string why = configure_from_probe(w, node); !why.empty()) {
          if (w.fault.empty()) w.fault = "configuration refused: node " + std::to_string(node.id) + ": " + why;
          break;
        }
        if (frame) (void)send(*frame);
        c.start(&node.steps);
        frame = c.poll(now_us);
        break;
      }
      node.configured = true;
      if (&node == &w.encoder_node) {
        w.encoder.set_range(c.read_value(0x6002, 0).value_or(0));
      }
      node.last_start_sent_us = now_us;
      if (frame) (void)send(*frame);
      return send(make_nmt(NmtCommand::kStart, node.id));
    case NodeConfigurator::State::kFailed:
      if (w.fault.empty()) w.fault = "configuration refused: " + c.error();
      break;
    case NodeConfigurator::State::kNoAnswer:
      node.configure_at_us = now_us + config_.resend_interval_us;  // not there yet: try again
      break;
    default: break;
  }
  return frame ? send(*frame) : hal::Status::Ok();
}

hal::Status CanopenWinchBank::service_error_code(Winch& w, hal::TimeUs now_us) {
  if (w.drive.drive_state() != hal::DriveState::kFault) {
    w.error_code_asked = false;
    w.error_code_value = 0;
    if (!w.error_code.empty()) w.error_code.clear();
    return hal::Status::Ok();
  }
  NodeConfigurator& c = w.drive_node.configurator;
  if (!w.error_code_asked) {
    if (!w.drive_node.configured || c.state() == NodeConfigurator::State::kRunning) return hal::Status::Ok();
    w.error_code_asked = true;
    c.start(&w.error_code_steps);
  } else if (c.state() != NodeConfigurator::State::kRunning || !c.runs(&w.error_code_steps)) {
    return hal::Status::Ok();  // read (or failed) once for this fault, or the channel was taken over
  }
  std::optional<CanFrame> frame = c.poll(now_us);
  if (c.state() == NodeConfigurator::State::kDone) {
    const std::uint32_t code = c.read_value(0x603F, 0).value_or(0);
    w.error_code_value = static_cast<std::uint16_t>(code);
    char text[80];
    std::snprintf(text, sizeof(text), "0x603F = 0x%04X (%s)", static_cast<unsigned>(code),
                  emergency_text(static_cast<std::uint16_t>(code)));
    w.error_code = text;
  }
  return frame ? send(*frame) : hal::Status::Ok();
}

hal::Status CanopenWinchBank::service_enable(Winch& w, hal::TimeUs now_us) {
  const bool writing = w.enable == EnableStep::kCheckMode;
  if ((!writing && w.enable != EnableStep::kAwaitMode) || !w.drive_node.configured) return hal::Status::Ok();
  if (!w.fault.empty()) {
    w.enable = EnableStep::kNone;
    return hal::Status::Ok();
  }
  NodeConfigurator& c = w.drive_node.configurator;
  if (!w.mode_check_started) {
    if (!writing && now_us < w.mode_read_at_us) return hal::Status::Ok();
    if (c.state() == NodeConfigurator::State::kRunning) return hal::Status::Ok();  // the channel is busy
    if (writing) {
      // The limits are placed from the present drive and encoder positions.
      if (!w.encoder.valid() || w.drive_node.last_pdo_us < 0) return hal::Status::Ok();
      w.enable_steps = enable_steps(w);
    }
    w.mode_check_started = true;
    c.start(writing ? &w.enable_steps : &mode_display_steps_);
  }
  std::optional<CanFrame> frame = c.poll(now_us);
  switch (c.state()) {
    case NodeConfigurator::State::kDone: {
      w.mode_check_started = false;
      if (writing) {
        w.enable = EnableStep::kAwaitMode;
        w.mode_deadline_us = now_us + config_.mode_switch_timeout_us;
        w.mode_read_at_us = now_us;
        break;
      }
      const SdoStep& display = mode_display_steps_[0];
      const std::uint32_t shown = c.read_value(display.index, display.subindex).value_or(0);
      if (shown == mode_wanted_) {
        w.enable = EnableStep::kGoalSet;
        w.drive.set_goal(Cia402Drive::Goal::kEnabled);
      } else if (now_us >= w.mode_deadline_us) {
        char text[200];
        std::snprintf(text, sizeof(text),
                      "enable refused: node %d: 0x%04X (%s) still %u %lld ms after the mode was written, expected %u",
                      w.drive_node.id, display.index, display.what, shown,
                      static_cast<long long>(config_.mode_switch_timeout_us / 1000), mode_wanted_);
        w.fault = text;
        w.enable = EnableStep::kNone;
      } else {
        w.mode_read_at_us = now_us + config_.mode_poll_interval_us;  // the drive is still switching
      }
      break;
    }
    case NodeConfigurator::State::kFailed:
      w.mode_check_started = false;
      w.fault = "enable refused: " + c.error();
      w.enable = EnableStep::kNone;
      break;
    case NodeConfigurator::State::kNoAnswer:
      w.mode_check_started = false;  // try again
      break;
    default: break;
  }
  return frame ? send(*frame) : hal::Status::Ok();
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
  if (node.id == 0) return true;
  const bool heartbeat_fresh =
      node.last_heartbeat_us >= 0 && now_us_ - node.last_heartbeat_us <= config_.heartbeat_timeout_us;
  const bool pdo_fresh = node.last_pdo_us >= 0 && now_us_ - node.last_pdo_us <= config_.heartbeat_timeout_us;
  return node.configured && heartbeat_fresh && node.nmt_state == NmtState::kOperational && pdo_fresh;
}

double CanopenWinchBank::payout_m(const Winch& w) const {
  const std::size_t i = static_cast<std::size_t>(&w - winches_.data());
  const CanWinchConfig& c = config_.winches[i];
  const double m_per_count = c.encoder_node_id == 0 ? c.drive_m_per_count : c.encoder_m_per_count;
  return static_cast<double>(w.encoder.counts()) * m_per_count;
}

hal::WinchStatus CanopenWinchBank::status(int winch) const {
  if (winch < 0 || winch >= winch_count()) std::abort();  // caller's broken invariant (hal/winch_bank.h)
  const Winch& w = winches_[static_cast<std::size_t>(winch)];
  hal::WinchStatus s;
  s.payout_m = payout_m(w);
  s.position_valid = w.encoder.valid();
  s.fault = !w.fault.empty();
  s.position_time_us = w.encoder_time_us;
  s.target_payout_m = w.target_payout_m;
  hal::TimeUs oldest_us = std::numeric_limits<hal::TimeUs>::max();
  bool heard_all = true;
  for (const Node* node : {&w.drive_node, &w.encoder_node}) {
    if (node->id == 0) continue;
    // Until configured a node is not there yet for the caller (hal's -1 age).
    heard_all = heard_all && node->configured && node->last_heartbeat_us >= 0 && node->last_pdo_us >= 0;
    oldest_us = std::min(oldest_us, node->last_heartbeat_us);
  }
  s.heartbeat_age_us = heard_all ? now_us_ - oldest_us : -1;
  s.alive = transport_ != nullptr && heard_all && node_alive(w.drive_node) && node_alive(w.encoder_node);
  s.drive = w.drive.drive_state();
  s.target_reached = w.drive.target_reached();
  return s;
}

}  // namespace cdpr::drivers::can
