#include "virtual-robot/canopen_nodes.h"

#include <algorithm>
#include <cmath>

namespace cdpr::virtual_robot {
namespace {

BusFrame to_bus(const drivers::can::CanFrame& frame) { return BusFrame{frame.id, frame.len, frame.data}; }
drivers::can::CanFrame from_bus(const BusFrame& frame) { return drivers::can::CanFrame{frame.id, frame.len, frame.data}; }

}  // namespace

const std::vector<std::string>& canopen_quirk_names() {
  static const std::vector<std::string> kNames{"two-tpdo-encoder", "rtr-bit30", "no-type-255", "rpm-units"};
  return kNames;
}

std::optional<CanopenQuirks> parse_canopen_quirks(const std::string& names, std::string& error) {
  CanopenQuirks quirks;
  const CanopenQuirks plain;
  std::size_t at = 0;
  while (at <= names.size()) {
    const std::size_t comma = std::min(names.find(',', at), names.size());
    const std::string name = names.substr(at, comma - at);
    at = comma + 1;
    if (name.empty() || name == "none") continue;
    std::string& file = name == "two-tpdo-encoder" ? quirks.encoder_eds : quirks.drive_eds;
    const std::string& before = name == "two-tpdo-encoder" ? plain.encoder_eds : plain.drive_eds;
    if (std::find(canopen_quirk_names().begin(), canopen_quirk_names().end(), name) == canopen_quirk_names().end()) {
      error = "unknown quirk '" + name + "' (" + "two-tpdo-encoder, rtr-bit30, no-type-255, rpm-units)";
      return std::nullopt;
    }
    if (file != before) {
      error = "'" + name + "' and another profile both choose the " +
              (name == "two-tpdo-encoder" ? "encoders'" : "drives'") + " EDS file: one per device";
      return std::nullopt;
    }
    file = name == "two-tpdo-encoder" ? "cdpr-virtual-encoder-two-tpdo.eds"
                                      : "cdpr-virtual-drive-" + std::string(name == "rpm-units" ? "rpm" : name) + ".eds";
  }
  return quirks;
}

namespace {

DriveDefaults drive_defaults(const NodeLayout& layout) {
  constexpr double kPi = 3.14159265358979323846;
  DriveDefaults drive;
  drive.eds = layout.drive_eds;
  if (layout.drive_power_on_mode != 0) {
    drive.stored[object_key(0x6060, 0)] = static_cast<std::uint8_t>(layout.drive_power_on_mode);
  }
  drive.counts_per_rev = kPi * layout.drum_diameter_m / layout.gear_ratio / layout.drive_m_per_count;
  return drive;
}

EncoderDefaults encoder_defaults(const NodeLayout& layout) {
  EncoderDefaults encoder;
  encoder.eds = layout.encoder_eds;
  encoder.stored[object_key(0x6002, 0)] = layout.encoder_range_counts;
  return encoder;
}

}  // namespace

void CanopenNodes::apply(const CanopenQuirks& quirks, NodeLayout& layout) {
  layout.drive_eds = shipped_eds(quirks.drive_eds);
  layout.encoder_eds = shipped_eds(quirks.encoder_eds);
}

std::string CanopenNodes::check(const NodeLayout& layout) {
  std::string why = Cia402Device::check(layout.drive_node_id[0], drive_defaults(layout));
  return why.empty() ? Cia406Device::check(layout.encoder_node_id[0], encoder_defaults(layout)) : why;
}

CanopenNodes::CanopenNodes(const NodeLayout& layout, RobotPhysics& physics, sim::Rng rng, hal::TimeUs now_us)
    : layout_(layout), physics_(physics), rng_(rng) {
  (void)now_us;
  const DriveDefaults drive = drive_defaults(layout);
  const EncoderDefaults encoder = encoder_defaults(layout);
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
