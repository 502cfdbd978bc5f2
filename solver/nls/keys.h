#pragma once
// Typed keys for the variables of the calibration factor graph.

#include <compare>
#include <cstdint>
#include <string>

namespace cdpr {

enum class VariableKind : std::uint8_t {
  kPose,            // world_T_platform of static pose k, SE(3), 6-dim tangent
  kReferenceForce,  // (f_h, f_v) of the reference cable at pose k [N]
  kAnchor,          // pulley exit point of cable i, world frame [m]
  kOffset,          // encoder offset of cable i [m]
  kEffect,          // parameters of an extra model term, by effect index
};

struct Key {
  VariableKind kind = VariableKind::kPose;
  int index = 0;
  auto operator<=>(const Key&) const = default;
};

inline Key PoseKey(int k) { return {VariableKind::kPose, k}; }
inline Key ReferenceForceKey(int k) { return {VariableKind::kReferenceForce, k}; }
inline Key AnchorKey(int i) { return {VariableKind::kAnchor, i}; }
inline Key OffsetKey(int i) { return {VariableKind::kOffset, i}; }
inline Key EffectKey(int e) { return {VariableKind::kEffect, e}; }

std::string to_string(const Key& key);  // "pose[3]", "anchor[1]", ...

}  // namespace cdpr
