#include "virtual-robot/canopen_nodes.h"

#include <algorithm>
#include <cmath>

namespace cdpr::virtual_robot {
namespace {

BusFrame to_bus(const drivers::can::CanFrame& frame) { return BusFrame{frame.id, frame.len, frame.data}; }
drivers::can::CanFrame from_bus(const BusFrame& frame) { return drivers::can::CanFrame{frame.id, frame.len, frame.data}; }

}  // namespace

std::optional<CanopenQuirks> parse_canopen_quirks(const std::string& names) {
  CanopenQuirks quirks;
  std::size_t at = 0;
  while (at <= names.size()) {
    const std::size_t comma = std::min(names.find(',', at), names.size());
    const std::string name = names.substr(at, comma - at);
    at = comma + 1;
    if (name.empty() || name == "none") continue;
    if (name == "two-tpdo-encoder") {
      quirks.two_tpdo_encoder = true;
    } else if (name == "rtr-bit30") {
      quirks.rtr_bit30 = true;
    } else if (name == "no-type-255") {
      quirks.no_type_255 = true;
    } else if (name == "rpm-units") {
      quirks.rpm_units = true;
    } else {
      return std::nullopt;
    }
  }
  return quirks;
}

CanopenNodes::CanopenNodes(const NodeLayout& layout, RobotPhysics& physics, sim::Rng rng, hal::TimeUs now_us)
    : layout_(layout), physics_(physics), rng_(rng) {
  (void)now_us;
  DriveDefaults drive;
  drive.power_on_mode = layout.drive_power_on_mode;
  EncoderDefaults encoder;
  encoder.measuring_range = layout.encoder_range_counts;
  const CanopenQuirks& q = layout.quirks;
  for (CommunicationQuirks* c : {&drive.quirks, &encoder.quirks}) {
    c->cob_id_bit30_fixed = q.rtr_bit30;
    c->no_type_255 = q.no_type_255;
  }
  if (q.two_tpdo_encoder) {
    encoder.quirks.tpdo_count = 2;
    encoder.quirks.rpdo_count = 0;
  }
  if (q.rpm_units) {
    constexpr double kPi = 3.14159265358979323846;
    drive.rpm_units = true;
    drive.counts_per_rev = kPi * layout.drum_diameter_m / layout.gear_ratio / layout.drive_m_per_count;
  }
  for (int i = 0; i < kCableCount; ++i) {
    drives_[i] = std::make_unique<Cia402Device>(layout.drive_node_id[i], drive);
    drives_[i]->set_initial_position(physics.payout_m(i) / layout.drive_m_per_count);
    encoders_[i] = std::make_unique<Cia406Device>(layout.encoder_node_id[i], encoder);
  }
}

void CanopenNodes::silence(int node_id, bool silent) {
  for (int i = 0; i < kCableCount; ++i) {
    if (drives_[i]->node_id() == node_id) drives_[i]->set_silent(silent);
    if (encoders_[i]->node_id() == node_id) encoders_[i]->set_silent(silent);
  }
}

void CanopenNodes::on_frame(const drivers::can::CanFrame& frame, hal::TimeUs now_us) {
  const BusFrame bus = to_bus(frame);
  for (int i = 0; i < kCableCount; ++i) {
    drives_[i]->on_frame(bus, now_us);
    encoders_[i]->on_frame(bus, now_us);
  }
}

void CanopenNodes::advance(double dt_s) {
  for (int i = 0; i < kCableCount; ++i) {
    drives_[i]->advance(dt_s);
    physics_.set_payout(i, drives_[i]->position_counts() * layout_.drive_m_per_count);
  }
}

bool CanopenNodes::winches_still() const {
  for (const auto& d : drives_) {
    if (!d->at_rest()) return false;
  }
  return true;
}

bool CanopenNodes::any_drive_braking() const {
  for (const auto& d : drives_) {
    if (d->braking()) return true;
  }
  return false;
}

bool CanopenNodes::axes_still() const {
  for (const auto& d : drives_) {
    if (!d->axis_still()) return false;
  }
  return true;
}

void CanopenNodes::poll(hal::TimeUs now_us, std::vector<drivers::can::CanFrame>& out) {
  scratch_.clear();
  for (int i = 0; i < kCableCount; ++i) {
    const double reading_m = physics_.payout_m(i) + encoder_slip_m_[i] + layout_.encoder_noise_m * rng_.normal();
    encoders_[i]->set_position_counts(std::llround(reading_m / layout_.encoder_m_per_count));
    drives_[i]->poll(now_us, scratch_);
    encoders_[i]->poll(now_us, scratch_);
  }
  for (const BusFrame& frame : scratch_) out.push_back(from_bus(frame));
}

}  // namespace cdpr::virtual_robot
