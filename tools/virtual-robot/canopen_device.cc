#include "virtual-robot/canopen_device.h"

#include <algorithm>
#include <cstdio>
#include <utility>

namespace cdpr::virtual_robot {
namespace {

constexpr std::uint32_t kPdoInvalid = 0x80000000u;
constexpr std::uint32_t kPdoNoRtr = 0x40000000u;
constexpr std::uint16_t kEmcyHeartbeat = 0x8130;     // CiA 301: life guard or heartbeat error
constexpr std::uint16_t kEmcyPdoLength = 0x8210;     // PDO not processed due to length error
constexpr std::uint8_t kErrorRegisterCommunication = 0x10;

std::uint32_t le32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

bool is_pdo_communication(std::uint16_t index) {
  return (index >= 0x1400 && index <= 0x1403) || (index >= 0x1800 && index <= 0x1803);
}
bool is_pdo_mapping(std::uint16_t index) {
  return (index >= 0x1600 && index <= 0x1603) || (index >= 0x1A00 && index <= 0x1A03);
}

int pdo_count(const ObjectDictionary& od, std::uint16_t first) {
  int n = 0;
  while (n < 4 && od.find(static_cast<std::uint16_t>(first + n), 1) != nullptr) ++n;
  return n;
}

std::string object_name(std::uint16_t index, std::uint8_t subindex) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%04X:%02X", index, subindex);
  return text;
}

}  // namespace

std::string CanopenDevice::check_communication_objects(const ObjectDictionary& od) {
  std::vector<std::pair<std::uint16_t, std::uint8_t>> needed{{0x1001, 0}, {0x1016, 1}, {0x1017, 0}};
  for (int n = 0; n < pdo_count(od, 0x1400); ++n) {
    for (std::uint8_t sub : {1, 2}) needed.emplace_back(0x1400 + n, sub);
    needed.emplace_back(0x1600 + n, 0);
  }
  for (int n = 0; n < pdo_count(od, 0x1800); ++n) {
    for (std::uint8_t sub : {1, 2, 3, 5}) needed.emplace_back(0x1800 + n, sub);
    needed.emplace_back(0x1A00 + n, 0);
  }
  for (const auto& [index, subindex] : needed) {
    if (od.find(index, subindex) == nullptr) return "no object " + object_name(index, subindex);
  }
  // A mapping's power-on entries must exist.
  for (std::uint16_t mapping = 0x1600; mapping <= 0x1A03; ++mapping) {
    const OdEntry* count = is_pdo_mapping(mapping) ? od.find(mapping, 0) : nullptr;
    if (count == nullptr) continue;
    for (std::uint8_t sub = 1; sub <= count->default_value; ++sub) {
      if (od.find(mapping, sub) == nullptr) return "no object " + object_name(mapping, sub) + " of the mapped count";
    }
  }
  return {};
}

CanopenDevice::CanopenDevice(int node_id, ObjectDictionary od)
    : node_id_(node_id), od_(std::move(od)), rpdo_count_(pdo_count(od_, 0x1400)), tpdo_count_(pdo_count(od_, 0x1800)) {}

void CanopenDevice::reset(bool communication_only) {
  od_.reset(communication_only);
  state_ = NodeState::kPreOperational;
  boot_up_pending_ = true;
  sdo_ = SdoSession{};
  next_heartbeat_us_ = -1;
  tpdo_next_event_us_ = {-1, -1, -1, -1};
  tpdo_sent_ = {};
  consumer_last_us_ = -1;
  if (!communication_only) on_reset();
}

void CanopenDevice::queue(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  BusFrame frame;
  frame.id = id;
  for (std::uint8_t b : bytes) frame.data[frame.len++] = b;
  outbox_.push_back(frame);
}

void CanopenDevice::emergency(std::uint16_t code, std::uint8_t error_register) {
  od_.set(0x1001, 0, error_register);
  emergencies_.push_back(code);
  if (state_ == NodeState::kStopped) return;
  queue(0x80 + static_cast<std::uint32_t>(node_id_),
        {static_cast<std::uint8_t>(code), static_cast<std::uint8_t>(code >> 8), error_register, 0, 0, 0, 0, 0});
}

void CanopenDevice::on_frame(const BusFrame& frame, hal::TimeUs now_us) {
  if (silent_) return;
  const auto id = static_cast<int>(frame.id);
  if (frame.id == 0x000) return on_nmt(frame);
  if (frame.id == 0x080 && frame.len <= 1) {  // SYNC
    if (state_ == NodeState::kOperational) {
      ++sync_count_;
      sync_pending_ = true;
    }
    return;
  }
  if (id > 0x700 && id <= 0x77F) return on_heartbeat_frame(id - 0x700, now_us);
  if (frame.id == 0x600 + static_cast<std::uint32_t>(node_id_)) {
    if (state_ != NodeState::kStopped) on_sdo(frame);
    return;
  }
  if (state_ != NodeState::kOperational) return;  // PDOs only when operational
  for (int n = 0; n < rpdo_count_; ++n) {
    const std::uint32_t cob = od_.get(static_cast<std::uint16_t>(0x1400 + n), 1);
    if ((cob & kPdoInvalid) == 0 && (cob & 0x7FF) == frame.id) on_rpdo_frame(n, frame, now_us);
  }
}

void CanopenDevice::on_nmt(const BusFrame& frame) {
  if (frame.len != 2 || (frame.data[1] != 0 && frame.data[1] != node_id_)) return;
  switch (frame.data[0]) {
    case 0x01: state_ = NodeState::kOperational; break;
    case 0x02: state_ = NodeState::kStopped; break;
    case 0x80: state_ = NodeState::kPreOperational; break;
    case 0x81: reset(false); break;
    case 0x82: reset(true); break;
    default: break;
  }
}

void CanopenDevice::on_heartbeat_frame(int producer, hal::TimeUs now_us) {
  const std::uint32_t consumer = od_.get(0x1016, 1);
  if (static_cast<int>((consumer >> 16) & 0x7F) != producer || (consumer & 0xFFFF) == 0) return;
  if (consumer_last_us_ >= 0) longest_consumer_gap_us_ = std::max(longest_consumer_gap_us_, now_us - consumer_last_us_);
  consumer_last_us_ = now_us;
}

void CanopenDevice::check_consumers(hal::TimeUs now_us) {
  const std::uint32_t consumer = od_.get(0x1016, 1);
  const hal::TimeUs time_us = 1000 * static_cast<hal::TimeUs>(consumer & 0xFFFF);
  if (consumer_last_us_ < 0 || time_us == 0 || now_us - consumer_last_us_ <= time_us) return;
  consumer_last_us_ = -1;  // armed again by the producer's next heartbeat
  emergency(kEmcyHeartbeat, kErrorRegisterCommunication | 0x01);
  on_heartbeat_lost(static_cast<int>((consumer >> 16) & 0x7F));
}

void CanopenDevice::sdo_reply(std::uint8_t command, std::uint16_t index, std::uint8_t subindex, std::uint32_t value) {
  queue(0x580 + static_cast<std::uint32_t>(node_id_),
        {command, static_cast<std::uint8_t>(index), static_cast<std::uint8_t>(index >> 8), subindex,
         static_cast<std::uint8_t>(value), static_cast<std::uint8_t>(value >> 8), static_cast<std::uint8_t>(value >> 16),
         static_cast<std::uint8_t>(value >> 24)});
}

void CanopenDevice::sdo_abort(std::uint16_t index, std::uint8_t subindex, std::uint32_t code) {
  sdo_.active = false;
  sdo_reply(0x80, index, subindex, code);
}

std::uint32_t CanopenDevice::check_pdo_write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value) const {
  // Strict devices change PDO parameters only in pre-operational.
  if (state_ == NodeState::kOperational) return abort_code::kDeviceState;
  if (is_pdo_communication(index) && subindex == 1) {
    const std::uint32_t now = od_.get(index, 1);
    const bool valid_now = (now & kPdoInvalid) == 0, valid_after = (value & kPdoInvalid) == 0;
    if (valid_now && valid_after && (now & 0x7FF) != (value & 0x7FF)) return abort_code::kInvalidValue;
    if ((value & 0x7FF) == 0 || (value & 0x1FFFF800) != 0) return abort_code::kInvalidValue;
  }
  if (is_pdo_communication(index) && subindex == 2 && value > 240 && value < 254) return abort_code::kInvalidValue;
  if (is_pdo_mapping(index)) {
    const auto communication = static_cast<std::uint16_t>(index - 0x200);
    if ((od_.get(communication, 1) & kPdoInvalid) == 0) return abort_code::kDeviceState;  // PDO still valid
    if (subindex != 0) return od_.get(index, 0) != 0 ? abort_code::kDeviceState : 0;
    if (value > 8) return abort_code::kInvalidValue;
    std::uint32_t bits = 0;
    for (std::uint8_t sub = 1; sub <= value; ++sub) {
      if (od_.find(index, static_cast<std::uint8_t>(sub)) == nullptr) return abort_code::kInvalidValue;  // fewer entries
      const std::uint32_t entry = od_.get(index, sub);
      const OdEntry* mapped = od_.find(static_cast<std::uint16_t>(entry >> 16), static_cast<std::uint8_t>(entry >> 8));
      const bool rx = index < 0x1A00;
      if (mapped == nullptr || !mapped->mappable || (entry & 0xFF) != 8u * mapped->size ||
          (rx && mapped->access == Access::kReadOnly)) {
        return abort_code::kNotMappable;
      }
      bits += entry & 0xFF;
    }
    if (bits > 64) return abort_code::kPdoTooLong;
  }
  return 0;
}

std::uint32_t CanopenDevice::write(std::uint16_t index, std::uint8_t subindex, std::uint32_t value, std::uint32_t size) {
  OdEntry* e = od_.find(index, subindex);
  if (e == nullptr) return od_.check_exists(index, subindex);
  if (e->access == Access::kReadOnly) return abort_code::kReadOnly;
  if (size != 0 && size != e->size) return abort_code::kLength;
  if (e->size < 4) value &= (1u << (8 * e->size)) - 1;
  if (const std::uint32_t code = ObjectDictionary::check_range(*e, value); code != 0) return code;
  // A device without RTR keeps bit 30 as its default has it.
  if (is_pdo_communication(index) && subindex == 1 && (e->default_value & kPdoNoRtr) != 0) value |= kPdoNoRtr;
  if (is_pdo_communication(index) || is_pdo_mapping(index)) {
    if (const std::uint32_t code = check_pdo_write(index, subindex, value); code != 0) return code;
  }
  if (const std::uint32_t code = check_write(index, subindex, value); code != 0) return code;
  e->value = value;
  if (index == 0x1017) next_heartbeat_us_ = -1;  // restart the producer with the new period
  if (index == 0x1016) consumer_last_us_ = -1;
  if (is_pdo_communication(index) && index >= 0x1800) tpdo_next_event_us_[index - 0x1800] = -1;
  after_write(index, subindex);
  return 0;
}

void CanopenDevice::on_sdo(const BusFrame& frame) {
  if (frame.len != 8) return;
  const std::uint8_t command = frame.data[0];
  const auto index = static_cast<std::uint16_t>(frame.data[1] | frame.data[2] << 8);
  const std::uint8_t subindex = frame.data[3];
  switch (command >> 5) {
    case 1: {  // initiate download
      sdo_.active = false;
      if ((command & 0x02) != 0) {  // expedited
        const std::uint32_t size = (command & 0x01) != 0 ? 4u - ((command >> 2) & 0x03) : 0u;
        std::uint32_t value = le32(&frame.data[4]);
        if (size != 0 && size < 4) value &= (1u << (8 * size)) - 1;
        if (const std::uint32_t code = write(index, subindex, value, size); code != 0) return sdo_abort(index, subindex, code);
        return sdo_reply(0x60, index, subindex, 0);
      }
      const OdEntry* e = od_.find(index, subindex);
      if (e == nullptr) return sdo_abort(index, subindex, od_.check_exists(index, subindex));
      const std::uint32_t size = (command & 0x01) != 0 ? le32(&frame.data[4]) : e->size;
      if (size != e->size) return sdo_abort(index, subindex, abort_code::kLength);
      sdo_ = SdoSession{true, index, subindex, size, {}, 0, false};
      return sdo_reply(0x60, index, subindex, 0);
    }
    case 0: {  // download segment
      if (!sdo_.active) return sdo_abort(index, subindex, abort_code::kCommand);
      if (((command & 0x10) != 0) != sdo_.toggle) return sdo_abort(sdo_.index, sdo_.subindex, abort_code::kToggle);
      const std::uint32_t n = 7u - ((command >> 1) & 0x07);
      for (std::uint32_t i = 0; i < n && sdo_.received < sdo_.bytes.size(); ++i) sdo_.bytes[sdo_.received++] = frame.data[1 + i];
      const std::uint8_t reply = static_cast<std::uint8_t>(0x20 | (sdo_.toggle ? 0x10 : 0));
      sdo_.toggle = !sdo_.toggle;
      if ((command & 0x01) == 0) {
        queue(0x580 + static_cast<std::uint32_t>(node_id_), {reply, 0, 0, 0, 0, 0, 0, 0});
        return;
      }
      sdo_.active = false;
      if (sdo_.received != sdo_.size) return sdo_abort(sdo_.index, sdo_.subindex, abort_code::kLength);
      if (const std::uint32_t code = write(sdo_.index, sdo_.subindex, le32(sdo_.bytes.data()), sdo_.size); code != 0) {
        return sdo_abort(sdo_.index, sdo_.subindex, code);
      }
      queue(0x580 + static_cast<std::uint32_t>(node_id_), {reply, 0, 0, 0, 0, 0, 0, 0});
      return;
    }
    case 2: {  // initiate upload: every object here fits an expedited answer
      sdo_.active = false;
      const OdEntry* e = od_.find(index, subindex);
      if (e == nullptr) return sdo_abort(index, subindex, od_.check_exists(index, subindex));
      return sdo_reply(static_cast<std::uint8_t>(0x43 | (4 - e->size) << 2), index, subindex, e->value);
    }
    case 4:  // abort from the client
      sdo_.active = false;
      return;
    default:
      return sdo_abort(index, subindex, abort_code::kCommand);
  }
}

void CanopenDevice::on_rpdo_frame(int pdo, const BusFrame& frame, hal::TimeUs now_us) {
  const auto mapping = static_cast<std::uint16_t>(0x1600 + pdo);
  const std::uint32_t count = od_.get(mapping, 0);
  std::uint32_t bytes = 0;
  for (std::uint8_t sub = 1; sub <= count; ++sub) bytes += (od_.get(mapping, sub) & 0xFF) / 8;
  if (frame.len < bytes) {
    emergency(kEmcyPdoLength, kErrorRegisterCommunication | 0x01);
    return;
  }
  std::uint32_t at = 0;
  for (std::uint8_t sub = 1; sub <= count; ++sub) {
    const std::uint32_t entry = od_.get(mapping, sub);
    const std::uint32_t size = (entry & 0xFF) / 8;
    std::uint32_t value = 0;
    for (std::uint32_t i = 0; i < size; ++i) value |= static_cast<std::uint32_t>(frame.data[at + i]) << (8 * i);
    at += size;
    od_.set(static_cast<std::uint16_t>(entry >> 16), static_cast<std::uint8_t>(entry >> 8), value);
  }
  on_rpdo(now_us);
}

bool CanopenDevice::tpdo_data(int pdo, BusFrame& frame) const {
  const std::uint32_t cob = od_.get(static_cast<std::uint16_t>(0x1800 + pdo), 1);
  if ((cob & kPdoInvalid) != 0) return false;
  frame = BusFrame{};
  frame.id = cob & 0x7FF;
  const auto mapping = static_cast<std::uint16_t>(0x1A00 + pdo);
  for (std::uint8_t sub = 1; sub <= od_.get(mapping, 0); ++sub) {
    const std::uint32_t entry = od_.get(mapping, sub);
    const std::uint32_t value = od_.get(static_cast<std::uint16_t>(entry >> 16), static_cast<std::uint8_t>(entry >> 8));
    for (std::uint32_t i = 0; i < (entry & 0xFF) / 8 && frame.len < 8; ++i) {
      frame.data[frame.len++] = static_cast<std::uint8_t>(value >> (8 * i));
    }
  }
  return true;
}

void CanopenDevice::send_tpdos(hal::TimeUs now_us, bool sync) {
  for (int n = 0; n < tpdo_count_; ++n) {
    BusFrame frame;
    if (!tpdo_data(n, frame)) continue;
    const auto comm = static_cast<std::uint16_t>(0x1800 + n);
    const std::uint32_t type = od_.get(comm, 2);
    const hal::TimeUs event_us = 1000 * static_cast<hal::TimeUs>(od_.get(comm, 5));
    const bool changed = !tpdo_sent_[n] || frame.len != tpdo_last_[n].len || frame.data != tpdo_last_[n].data;
    bool due = false;
    if (type >= 1 && type <= 240) {
      due = sync && sync_count_ % static_cast<int>(type) == 0;
    } else if (type == 0) {
      due = sync && changed;
    } else if (type >= 254) {
      const bool timer_due = event_us > 0 && (tpdo_next_event_us_[n] < 0 || now_us >= tpdo_next_event_us_[n]);
      // A change is sent no sooner than the inhibit time (0x1800:03, 100 us units) after the last frame.
      const hal::TimeUs inhibit_us = 100 * static_cast<hal::TimeUs>(od_.get(comm, 3));
      const bool inhibited = tpdo_sent_[n] && now_us - tpdo_last_us_[n] < inhibit_us;
      due = timer_due || (changed && !inhibited);
    }
    if (!due) continue;
    if (event_us > 0) tpdo_next_event_us_[n] = now_us + event_us;
    tpdo_last_[n] = frame;
    tpdo_last_us_[n] = now_us;
    tpdo_sent_[n] = true;
    outbox_.push_back(frame);
  }
}

void CanopenDevice::poll(hal::TimeUs now_us, std::vector<BusFrame>& out) {
  if (silent_) {
    outbox_.clear();
    return;
  }
  if (boot_up_pending_) {
    boot_up_pending_ = false;
    out.push_back(BusFrame{0x700 + static_cast<std::uint32_t>(node_id_), 1, {}});
  }
  out.insert(out.end(), outbox_.begin(), outbox_.end());
  outbox_.clear();
  check_consumers(now_us);
  const hal::TimeUs period_us = 1000 * static_cast<hal::TimeUs>(od_.get(0x1017, 0));
  if (period_us > 0 && (next_heartbeat_us_ < 0 || now_us >= next_heartbeat_us_)) {
    next_heartbeat_us_ = now_us + period_us;
    BusFrame heartbeat{0x700 + static_cast<std::uint32_t>(node_id_), 1, {}};
    heartbeat.data[0] = static_cast<std::uint8_t>(state_);
    out.push_back(heartbeat);
  }
  if (state_ == NodeState::kOperational) {
    before_tpdo(now_us);
    send_tpdos(now_us, sync_pending_);
  }
  sync_pending_ = false;
  out.insert(out.end(), outbox_.begin(), outbox_.end());
  outbox_.clear();
}

}  // namespace cdpr::virtual_robot
