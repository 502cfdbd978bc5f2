#include "virtual-robot/operation_faults.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

namespace cdpr::virtual_robot {
namespace {

std::optional<double> number(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

}  // namespace

std::optional<OperationFault> parse_operation_fault(const std::string& text, std::string& why) {
  const std::size_t at = text.find('@');
  const std::size_t colon = text.find(':', at == std::string::npos ? 0 : at);
  if (at == std::string::npos || colon == std::string::npos) {
    why = "'" + text + "': expected kind@time:key=value,... (e.g. slip@300:cable=2,size=0.02)";
    return std::nullopt;
  }
  const std::string kind = text.substr(0, at);
  OperationFault fault;
  static const std::map<std::string, OperationFault::Kind> kinds{{"slip", OperationFault::Kind::kEncoderSlip},
                                                                {"anchor", OperationFault::Kind::kAnchorMoved},
                                                                {"creep", OperationFault::Kind::kCableCreep},
                                                                {"payload", OperationFault::Kind::kPayload}};
  const auto found = kinds.find(kind);
  if (found == kinds.end()) {
    why = "'" + kind + "': unknown fault (slip, anchor, creep, payload)";
    return std::nullopt;
  }
  fault.kind = found->second;
  const std::optional<double> time = number(text.substr(at + 1, colon - at - 1));
  if (!time || *time < 0.0) {
    why = "'" + text + "': the time after @ must be a number of seconds >= 0";
    return std::nullopt;
  }
  fault.at_s = *time;
  std::map<std::string, double> values;
  for (std::size_t begin = colon + 1; begin <= text.size();) {
    const std::size_t comma = std::min(text.find(',', begin), text.size());
    const std::string pair = text.substr(begin, comma - begin);
    begin = comma + 1;
    const std::size_t equals = pair.find('=');
    const std::optional<double> value = equals == std::string::npos ? std::nullopt : number(pair.substr(equals + 1));
    if (!value) {
      why = "'" + pair + "': expected key=number";
      return std::nullopt;
    }
    values[pair.substr(0, equals)] = *value;
  }
  const auto take = [&](const char* key, double fallback) {
    const auto it = values.find(key);
    if (it == values.end()) return fallback;
    const double value = it->second;
    values.erase(it);
    return value;
  };
  if (fault.kind != OperationFault::Kind::kPayload) {
    const double cable = take("cable", -1.0);
    if (cable != std::floor(cable) || cable < 0.0 || cable >= kCableCount) {
      why = "'" + text + "': cable=0..3 is required";
      return std::nullopt;
    }
    fault.cable = static_cast<int>(cable);
  }
  switch (fault.kind) {
    case OperationFault::Kind::kEncoderSlip: fault.size_m = take("size", 0.0); break;
    case OperationFault::Kind::kAnchorMoved:
      fault.anchor_shift_m = {take("dx", 0.0), take("dy", 0.0), take("dz", 0.0)};
      break;
    case OperationFault::Kind::kCableCreep: fault.rate_mps = take("rate", 0.0); break;
    case OperationFault::Kind::kPayload: fault.mass_kg = take("mass", 0.0); break;
  }
  if (!values.empty()) {
    why = "'" + text + "': unknown key '" + values.begin()->first + "' for " + kind;
    return std::nullopt;
  }
  return fault;
}

std::string describe(const OperationFault& f) {
  const std::string cable = "cable " + std::to_string(f.cable);
  char text[160];
  switch (f.kind) {
    case OperationFault::Kind::kEncoderSlip:
      std::snprintf(text, sizeof text, "encoder slip of %s by %.4g m", cable.c_str(), f.size_m);
      break;
    case OperationFault::Kind::kAnchorMoved:
      std::snprintf(text, sizeof text, "anchor of %s moved by (%.4g, %.4g, %.4g) m", cable.c_str(),
                    f.anchor_shift_m.x(), f.anchor_shift_m.y(), f.anchor_shift_m.z());
      break;
    case OperationFault::Kind::kCableCreep:
      std::snprintf(text, sizeof text, "%s creeping at %.4g m/s", cable.c_str(), f.rate_mps);
      break;
    case OperationFault::Kind::kPayload:
      std::snprintf(text, sizeof text, "payload changed by %.4g kg", f.mass_kg);
      break;
  }
  return text;
}

void FaultSchedule::apply(double t_s, RobotPhysics& physics, CanopenNodes& nodes, std::vector<std::string>& began) {
  for (std::size_t k = 0; k < faults_.size(); ++k) {
    const OperationFault& f = faults_[k];
    if (t_s < f.at_s) continue;
    const bool first = !begun_[k];
    if (first) {
      begun_[k] = 1;
      began.push_back(describe(f));
      crept_until_s_[k] = f.at_s;
    }
    sim::TrueRobot robot = physics.robot();
    switch (f.kind) {
      case OperationFault::Kind::kEncoderSlip:
        if (first) nodes.add_encoder_slip(f.cable, f.size_m);
        break;
      case OperationFault::Kind::kAnchorMoved:
        if (!first) break;
        robot.robot.winches[f.cable].anchor_world += f.anchor_shift_m;
        physics.change_robot(robot);
        break;
      case OperationFault::Kind::kCableCreep:
        if (t_s - crept_until_s_[k] < kCreepStepS) break;
        // A longer cable for the same encoder reading: the true offset falls.
        robot.encoder_offset_m[f.cable] -= f.rate_mps * (t_s - crept_until_s_[k]);
        crept_until_s_[k] = t_s;
        physics.change_robot(robot);
        break;
      case OperationFault::Kind::kPayload:
        if (!first) break;
        robot.robot.platform_mass_kg += f.mass_kg;
        physics.change_robot(robot);
        break;
    }
  }
}

}  // namespace cdpr::virtual_robot
