// What the winch bank tells each node beyond the CiA defaults: the
// configuration fitted to the devices' EDS files, the drives' own velocity
// units (from their 0x60A9 or the EDS), the software position limits of
// every enable, and where an encoder's first reading is unwrapped to.
// Supervision lives in canopen_winch_bank.cc, drive commands in
// canopen_winch_bank_motion.cc.
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/can/canopen_winch_bank.h"

namespace cdpr::drivers::can {

double WinchMechanics::m_per_motor_rev() const {
  constexpr double kPi = 3.14159265358979323846;
  return drum_diameter_m > 0.0 && gear_ratio > 0.0 ? kPi * drum_diameter_m / gear_ratio : 0.0;
}

void CanopenWinchBank::fit_to_devices() {
  std::map<std::string, std::shared_ptr<const Eds>> loaded;
  for (std::size_t i = 0; i < winches_.size() && setup_error_.empty(); ++i) {
    Winch& w = winches_[i];
    const CanWinchConfig& c = config_.winches[i];
    load_eds(w.drive_node, c.drive_eds.empty() ? config_.drive.eds : c.drive_eds, loaded);
    if (c.encoder_node_id != 0) load_eds(w.encoder_node, c.encoder_eds.empty() ? config_.encoder.eds : c.encoder_eds, loaded);
    if (!setup_error_.empty()) break;
    std::string why;
    if (w.drive_node.eds) {
      why = fit_to_eds(*w.drive_node.eds, w.drive_node.probe_steps);
      // The units the EDS gives by default: a drive the configuration cannot fit is refused now, not at its first boot.
      const Eds& eds = *w.drive_node.eds;
      const auto value = [&eds](std::uint16_t index, std::uint8_t subindex) -> std::optional<std::uint32_t> {
        const EdsEntry* e = eds.find(index, subindex);
        if (e == nullptr || !e->default_value) return std::nullopt;
        return static_cast<std::uint32_t>(*e->default_value);
      };
      const EdsEntry* units = eds.find(0x60A9, 0);
      if (why.empty() && (units == nullptr || units->default_value)) {
        why = make_drive_steps(w, unit_objects(value), value(0x6080, 0));
      }
      if (!why.empty()) setup_error_ = "node " + std::to_string(c.drive_node_id) + ": " + why;
    }
    if (setup_error_.empty() && w.encoder_node.eds) {
      why = fit_to_eds(*w.encoder_node.eds, w.encoder_node.steps);
      if (!why.empty()) setup_error_ = "node " + std::to_string(c.encoder_node_id) + ": " + why;
    }
  }
}

void CanopenWinchBank::load_eds(Node& node, const std::string& path,
                                std::map<std::string, std::shared_ptr<const Eds>>& loaded) {
  if (path.empty()) return;
  if (auto it = loaded.find(path); it != loaded.end()) {
    node.eds = it->second;
    return;
  }
  std::string error;
  std::optional<Eds> eds = Eds::load(path, error);
  if (!eds) {
    setup_error_ = "node " + std::to_string(node.id) + ": " + error;
    return;
  }
  node.eds = loaded[path] = std::make_shared<const Eds>(std::move(*eds));
}

std::string CanopenWinchBank::nodes_without_eds() const {
  std::string drives, encoders;
  for (const Winch& w : winches_) {
    if (!w.drive_node.eds) drives += (drives.empty() ? "" : ", ") + std::to_string(w.drive_node.id);
    if (w.encoder_node.id != 0 && !w.encoder_node.eds) {
      encoders += (encoders.empty() ? "" : ", ") + std::to_string(w.encoder_node.id);
    }
  }
  std::string text = drives.empty() ? "" : "drives " + drives;
  if (!encoders.empty()) text += (text.empty() ? "" : "; ") + ("encoders " + encoders);
  return text;
}

DriveUnitObjects CanopenWinchBank::unit_objects(
    const std::function<std::optional<std::uint32_t>(std::uint16_t, std::uint8_t)>& value) {
  DriveUnitObjects o;
  o.si_unit_velocity = value(0x60A9, 0);
  o.si_unit_acceleration = value(0x60AA, 0);
  o.gear_motor_revs = value(0x6091, 1);
  o.gear_shaft_revs = value(0x6091, 2);
  o.velocity_numerator = value(0x6096, 1);
  o.velocity_divisor = value(0x6096, 2);
  o.acceleration_numerator = value(0x6097, 1);
  o.acceleration_divisor = value(0x6097, 2);
  return o;
}

std::string CanopenWinchBank::configure_from_probe(Winch& w, Node& node) {
  const NodeConfigurator& probe = node.configurator;
  const auto value = [&probe](std::uint16_t index, std::uint8_t subindex) { return probe.read_value(index, subindex); };
  return make_drive_steps(w, unit_objects(value), probe.read_value(0x6080, 0));
}

std::string CanopenWinchBank::make_drive_steps(Winch& w, const DriveUnitObjects& unit_objects,
                                               std::optional<std::uint32_t> max_motor_speed) {
  const std::size_t i = static_cast<std::size_t>(&w - winches_.data());
  const CanWinchConfig& c = config_.winches[i];
  std::string why;
  const std::optional<DriveUnits> units =
      drive_units(unit_objects, c.drive_m_per_count, config_.mechanics.m_per_motor_rev(), why);
  if (!units) return why;
  const std::uint32_t velocity = drive_value(*units, config_.drive.profile_velocity_mps);
  if (max_motor_speed && velocity > *max_motor_speed) {
    // The drive would clamp (or refuse) it, and a clamped winch leaves the coordinated line.
    return "profile_velocity_mps " + std::to_string(config_.drive.profile_velocity_mps) + " m/s is " +
           std::to_string(velocity) + " " + units->name + ", above its max motor speed 0x6080 = " +
           std::to_string(*max_motor_speed) + " " + units->name;
  }
  std::vector<SdoStep> steps =
      drive_configuration(c.drive_node_id, config_.master_node_id, c.drive_m_per_count, *units, config_.drive);
  if (w.drive_node.eds) {
    if (std::string problem = fit_to_eds(*w.drive_node.eds, steps); !problem.empty()) return problem;
  }
  w.units = *units;
  w.drive_node.steps = std::move(steps);
  return {};
}

std::int64_t CanopenWinchBank::payout_centre_counts(const Winch& w) const {
  const std::size_t i = static_cast<std::size_t>(&w - winches_.data());
  const CanWinchConfig& c = config_.winches[i];
  const double m_per_count = c.encoder_node_id == 0 ? c.drive_m_per_count : c.encoder_m_per_count;
  const double centre = std::round(0.5 * (config_.min_payout_m + config_.max_payout_m) / m_per_count);
  // No (finite) payout range: the first reading is taken nearest zero.
  return std::isfinite(centre) && std::abs(centre) < 1e15 ? static_cast<std::int64_t>(centre) : 0;
}

std::vector<SdoStep> CanopenWinchBank::enable_steps(const Winch& w) const {
  std::vector<SdoStep> steps = mode_write_steps_;  // 0x6061 is read after these, until it shows the mode
  const std::size_t i = static_cast<std::size_t>(&w - winches_.data());
  const double m_per_count = config_.winches[i].drive_m_per_count;
  const double here = static_cast<double>(w.drive.actual_counts()), payout = payout_m(w);
  const auto counts = [&](double payout_limit_m, double fallback) {
    const double c = std::round(here + (payout_limit_m - payout) / m_per_count);
    if (!std::isfinite(c) || c < std::numeric_limits<std::int32_t>::min() || c > std::numeric_limits<std::int32_t>::max()) {
      return fallback;  // beyond what the drive counts: its whole range on that side
    }
    return c;
  };
  constexpr double kMin = std::numeric_limits<std::int32_t>::min(), kMax = std::numeric_limits<std::int32_t>::max();
  const double margin = config_.position_limit_margin_m;
  // A negative m_per_count turns the payout range over in drive counts.
  const bool forward = m_per_count > 0.0;
  const double lo = counts(forward ? config_.min_payout_m - margin : config_.max_payout_m + margin, kMin);
  const double hi = counts(forward ? config_.max_payout_m + margin : config_.min_payout_m - margin, kMax);
  steps.push_back({SdoStep::Kind::kWriteVerify, 0x607D, 1, 4,
                   static_cast<std::uint32_t>(static_cast<std::int32_t>(lo)), "software position limit min"});
  steps.push_back({SdoStep::Kind::kWriteVerify, 0x607D, 2, 4,
                   static_cast<std::uint32_t>(static_cast<std::int32_t>(hi)), "software position limit max"});
  return steps;
}

}  // namespace cdpr::drivers::can
